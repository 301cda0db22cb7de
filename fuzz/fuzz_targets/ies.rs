//! Fuzz target: the IES reader must never panic, and whatever it accepts must expand to a diagram
//! (or fail cleanly) and survive a write/read round trip.
#![no_main]

use gonio::photometry::{read, write_ies, FileFormat, TiltResolver, WriteMeta};
use libfuzzer_sys::fuzz_target;

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
    if let Ok(p) = read(data, FileFormat::Ies, &FixedTilt) {
        let _ = p.max_intensity_cd();
        if let Ok(d) = p.to_diagram() {
            let _ = d.integral();
            // The round trip is checked on small diagrams only, to keep the run fast (type A/B
            // files always expand to 0.5° × 1° grids).
            if d.values().len() > 4096 {
                return;
            }
            let text = write_ies(&d, &WriteMeta::default());
            let back = read(text.as_bytes(), FileFormat::Ies, &FixedTilt)
                .expect("written IES must read back");
            let d2 = back.to_diagram().expect("written IES must expand");
            assert_eq!(d2.values(), d.values());
        }
    }
});
