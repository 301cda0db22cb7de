//! Fuzz target: the PFM reader must never panic; what it accepts must be finite and write back
//! to the same pixels (both byte orders).
#![no_main]

use gonio::image::{read_pfm, write_pfm};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = read_pfm(data) {
        assert!(img.rgb().iter().all(|v| v.is_finite()));
        if img.width() * img.height() > 1 << 16 {
            return;
        }
        for big in [false, true] {
            let back = read_pfm(&write_pfm(&img, false, big)).expect("written PFM must read back");
            assert_eq!(back.rgb(), img.rgb());
        }
    }
});
