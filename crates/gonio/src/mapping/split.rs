//! The split sphere layout's rule (docs/DERIVATION.md §10.1), written once for the scalar paths of
//! [`super::SphereMap`] and its batch paths (`soa_maps.rs`), in any element type: which hemisphere
//! map serves a point of the square or a direction, how u is rescaled into that map's square and
//! back, and that rounding never carries a lower-map point across the seam u = P_lower.

use super::simd::Elem;

/// The hemisphere map of a split layout that serves a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    /// The lower map (its directions mirrored to z ≤ 0).
    Lower = 0,
    /// The upper map.
    Upper = 1,
}

/// The rule of a split layout with lower-map probability P_lower and the maps it has (one at
/// least): u < P_lower goes to the lower map, the rest to the upper one.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SplitRule {
    p_lower: f64,
    has_upper: bool,
    has_lower: bool,
}

impl SplitRule {
    /// Both maps, the lower one with probability `p_lower` ∈ (0, 1).
    pub(crate) fn both(p_lower: f64) -> Self {
        SplitRule {
            p_lower,
            has_upper: true,
            has_lower: true,
        }
    }
    /// The upper map only (P_lower = 0).
    pub(crate) fn upper_only() -> Self {
        SplitRule {
            p_lower: 0.0,
            has_upper: true,
            has_lower: false,
        }
    }
    /// The lower map only (P_lower = 1).
    pub(crate) fn lower_only() -> Self {
        SplitRule {
            p_lower: 1.0,
            has_upper: false,
            has_lower: true,
        }
    }

    /// P_lower: the probability of the lower map (0 without one, 1 without an upper map).
    pub(crate) fn p_lower(&self) -> f64 {
        self.p_lower
    }

    /// The same rule with P_lower rounded to f32 (the float32 map's rule, and that of its exact
    /// reference, which evaluates it in f64).
    pub(crate) fn rounded_f32(self) -> Self {
        SplitRule {
            p_lower: self.p_lower as f32 as f64,
            ..self
        }
    }

    /// The side that serves a direction with this z: the lower map for z < 0, and for z = ±0 (the
    /// horizon, which both maps share with equal values there) when there is no upper map.
    #[inline]
    pub(crate) fn side_of<T: Elem>(&self, z: T) -> Side {
        if z < T::ZERO || (z == T::ZERO && !self.has_upper) {
            Side::Lower
        } else {
            Side::Upper
        }
    }

    /// The side that serves the square's first coordinate `u` and `u` rescaled into that map's
    /// square (with one map only, `u` unchanged), in `T`'s arithmetic.
    #[inline]
    pub(crate) fn split_u<T: Elem>(&self, u: T) -> (Side, T) {
        match (self.has_lower, self.has_upper) {
            (true, true) => {
                let p = T::from_f64(self.p_lower);
                if u < p {
                    (Side::Lower, (u / p).min(T::ONE))
                } else {
                    (Side::Upper, ((u - p) / (T::ONE - p)).clamp(T::ZERO, T::ONE))
                }
            }
            (true, false) => (Side::Lower, u),
            _ => (Side::Upper, u),
        }
    }

    /// The square's first coordinate of the point `w` of `side`'s map (the inverse of
    /// [`SplitRule::split_u`]). Rounding must not carry a lower-map point across the seam
    /// u = P_lower, which `split_u` would send to the upper map (the rim of the other side): such a
    /// point is put on the largest value below P_lower.
    #[inline]
    pub(crate) fn join_u<T: Elem>(&self, side: Side, w: T) -> T {
        let p = T::from_f64(self.p_lower);
        match side {
            Side::Lower if !self.has_upper => w,
            Side::Lower => {
                let u = w * p;
                if u >= p && p > T::ZERO {
                    p.next_below()
                } else {
                    u
                }
            }
            Side::Upper => (p + w * (T::ONE - p)).min(T::ONE),
        }
    }
}

/// A direction of the lower map's frame in the sphere's frame and back (z mirrored).
#[inline]
pub(crate) fn mirror<T: Elem>(d: [T; 3]) -> [T; 3] {
    [d[0], d[1], -d[2]]
}
