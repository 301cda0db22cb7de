//! Fuzz target: the OpenEXR reader must never panic; what it accepts must hold finite values
//! (EXR may store negative values, which the reader keeps), write back through PFM to the same
//! pixels, and (when small) build an environment map, or fail cleanly, that samples with finite
//! pdf.
#![no_main]

use gonio::image::{read_exr, read_pfm, write_pfm};
use libfuzzer_sys::fuzz_target;

#[path = "../common/envmap_case.rs"]
mod envmap_case;

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
        envmap_case::check_envmap(img);
    }
});
