//! Fuzz target: the OpenEXR reader must never panic; what it accepts must hold finite values
//! (EXR may store negative values, which the reader keeps), write back through PFM to the same
//! pixels, and (when small) build an environment map, or fail cleanly, that samples with finite
//! pdf.
#![no_main]

use gonio::envmap::EnvironmentMap;
use gonio::image::{read_exr, read_pfm, write_pfm};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = read_exr(data) {
        assert!(img.rgb().iter().all(|v| v.is_finite()));
        if img.width() * img.height() > 1 << 16 {
            return;
        }
        let back = read_pfm(&write_pfm(&img, false, false)).expect("written PFM must read back");
        assert_eq!((back.width(), back.height()), (img.width(), img.height()));
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(back.rgb()), bits(img.rgb()));
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
