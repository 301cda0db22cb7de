//! Fuzz target: the EULUMDAT reader must never panic, and whatever it accepts must expand to a
//! diagram (or fail cleanly) and survive a write/read round trip.
#![no_main]

use gonio::photometry::{write_ldt, FileFormat, NoTiltFiles};
use libfuzzer_sys::fuzz_target;

#[path = "../common/photometry_case.rs"]
mod photometry_case;

fuzz_target!(|data: &[u8]| {
    photometry_case::check(data, FileFormat::Eulumdat, &NoTiltFiles, write_ldt);
});
