//! Fuzz target: the Radiance `.hdr` reader must never panic; what it accepts must re-encode and
//! read back to the same size, and (when small and not black) build an environment map that
//! samples with agreeing pdf.
#![no_main]

use gonio::envmap::EnvironmentMap;
use gonio::image::{read_hdr, write_hdr};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = read_hdr(data) {
        assert!(img.rgb().iter().all(|v| v.is_finite() && *v >= 0.0));
        if img.width() * img.height() > 1 << 16 {
            return;
        }
        let back = read_hdr(&write_hdr(&img)).expect("written .hdr must read back");
        assert_eq!((back.width(), back.height()), (img.width(), img.height()));
        if let Ok(env) = EnvironmentMap::new(img) {
            for u in [[0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.3, 0.9]] {
                let s = env.sample(u);
                assert!(s.pdf.is_finite() && s.pdf >= 0.0);
            }
            // The float32 environment map of the same image samples too.
            let f = env.into_float32().expect("a small map has a float32 map");
            let (u, v) = ([0.0f32, 0.5, 1.0, 0.3], [0.0f32, 0.5, 1.0, 0.9]);
            let (mut x, mut y, mut z, mut p) = ([0f32; 4], [0f32; 4], [0f32; 4], [0f32; 4]);
            let mut rgb = [[0f32; 3]; 4];
            f.sample_soa(&u, &v, [&mut x, &mut y, &mut z], &mut p, &mut rgb);
            assert!(p.iter().all(|q| q.is_finite() && *q >= 0.0));
        }
    }
});
