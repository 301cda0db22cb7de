//! Fuzz target: the Radiance `.hdr` reader must never panic; what it accepts must re-encode and
//! read back to the same size, and (when small and not black) build an environment map that
//! samples with agreeing pdf.
#![no_main]

use gonio::image::{read_hdr, write_hdr};
use libfuzzer_sys::fuzz_target;

#[path = "../common/envmap_case.rs"]
mod envmap_case;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = read_hdr(data) {
        assert!(img.rgb().iter().all(|v| v.is_finite() && *v >= 0.0));
        if img.width() * img.height() > 1 << 16 {
            return;
        }
        let back = read_hdr(&write_hdr(&img)).expect("written .hdr must read back");
        assert_eq!((back.width(), back.height()), (img.width(), img.height()));
        envmap_case::check_envmap(img);
    }
});
