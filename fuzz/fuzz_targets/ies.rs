//! Fuzz target: the IES reader must never panic, and whatever it accepts must expand to a diagram
//! (or fail cleanly) and survive a write/read round trip.
#![no_main]

use gonio::photometry::{write_ies, FileFormat, TiltResolver};
use libfuzzer_sys::fuzz_target;

#[path = "../common/photometry_case.rs"]
mod photometry_case;

/// Serves a fixed TILT table for any name, so that the `TILT=<file>` path is exercised too.
struct FixedTilt;
impl TiltResolver for FixedTilt {
    fn resolve(&self, name: &str) -> Result<Vec<u8>, String> {
        if name.len() % 2 == 0 {
            Ok(b"1\n3\n0 45 90\n1 0.9 0.8\n".to_vec())
        } else {
            Err("absent".into())
        }
    }
}

fuzz_target!(|data: &[u8]| {
    photometry_case::check(data, FileFormat::Ies, &FixedTilt, write_ies);
});
