//! What the image fuzz targets (`hdr`, `exr`) check of an accepted small image: the environment
//! map builds or fails cleanly, and its float64 and float32 maps sample four points with finite
//! densities ≥ 0.

use gonio::envmap::EnvironmentMap;
use gonio::image::Image;

/// Builds `img`'s environment map (an error is fine) and samples it in both precisions.
pub fn check_envmap(img: Image) {
    let Ok(env) = EnvironmentMap::new(img) else {
        return;
    };
    for u in [[0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.3, 0.9]] {
        let s = env.sample(u);
        // Finite input gives finite output (issue 40): pdf, direction and radiance.
        assert!(s.pdf.is_finite() && s.pdf >= 0.0);
        assert!(s.direction.iter().all(|c| c.is_finite()));
        // (Finite, not ≥ 0: the EXR reader keeps negative values.)
        assert!(s.radiance.iter().all(|c| c.is_finite()));
    }
    let f = env.into_float32().expect("a small map has a float32 map");
    let (u, v) = ([0.0f32, 0.5, 1.0, 0.3], [0.0f32, 0.5, 1.0, 0.9]);
    let (mut x, mut y, mut z, mut p) = ([0f32; 4], [0f32; 4], [0f32; 4], [0f32; 4]);
    let mut rgb = [[0f32; 3]; 4];
    f.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut p, &mut rgb);
    assert!(p.iter().all(|q| q.is_finite() && *q >= 0.0));
    assert!([x, y, z].iter().flatten().all(|c| c.is_finite()));
    assert!(rgb.iter().flatten().all(|c| c.is_finite()));
}
