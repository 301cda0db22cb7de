//! Fuzz target: the EULUMDAT reader must never panic, and whatever it accepts must expand to a
//! diagram (or fail cleanly) and survive a write/read round trip.
#![no_main]

use gonio::photometry::{read, write_ldt, FileFormat, NoTiltFiles, WriteMeta};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) = read(data, FileFormat::Eulumdat, &NoTiltFiles) {
        let _ = p.max_intensity_cd();
        if let Ok(d) = p.to_diagram() {
            let _ = d.integral();
            // The round trip is checked on small diagrams only, to keep the run fast (type A/B
            // files always expand to 0.5° × 1° grids).
            if d.values().len() > 4096 {
                return;
            }
            let text = write_ldt(&d, &WriteMeta::default());
            let back = read(text.as_bytes(), FileFormat::Eulumdat, &NoTiltFiles)
                .expect("written LDT must read back");
            let d2 = back.to_diagram().expect("written LDT must expand");
            assert_eq!(d2.values(), d.values());
        }
    }
});
