//! The few operations on 3-vectors ([`Vec3`]) that the mesh, BRDF and environment-map code
//! needs, written once (a direction's normalisation, which can fail, is
//! [`crate::sampler::normalize`]).

use crate::sampler::Vec3;

/// a + b.
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s·a.
#[inline]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// a · b.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × b.
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// |a|, the Euclidean length.
#[inline]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cross_is_orthogonal_and_follows_the_right_hand() {
        let (a, b) = ([1.0, 2.0, 3.0], [-4.0, 0.5, 2.0]);
        let c = cross(a, b);
        assert_eq!(dot(c, a), 0.0);
        assert_eq!(dot(c, b), 0.0);
        assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
        assert_eq!(sub(add(a, b), b), a);
        assert_eq!(norm(scale([3.0, 0.0, 4.0], 2.0)), 10.0);
    }
}
