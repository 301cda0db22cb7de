//! What the photometric fuzz targets (`ies`, `ldt`) check of an input: the reader never panics,
//! and whatever it accepts expands to a diagram (or fails cleanly) and survives a write/read
//! round trip in its own format.

use gonio::photometry::{read, FileFormat, TiltResolver, WriteMeta};
use gonio::Diagram;

/// Reads `data` as `format`; an accepted small file is written back by `write` and must read
/// back to the same values.
pub fn check(
    data: &[u8],
    format: FileFormat,
    tilt: &dyn TiltResolver,
    write: fn(&Diagram, &WriteMeta) -> String,
) {
    let Ok(p) = read(data, format, tilt) else {
        return;
    };
    let _ = p.max_intensity_cd();
    let Ok(d) = p.to_diagram() else {
        return;
    };
    let _ = d.integral();
    // The round trip is checked on small diagrams only, to keep the run fast (type A/B files
    // always expand to 0.5° × 1° grids).
    if d.values().len() > 4096 {
        return;
    }
    let text = write(&d, &WriteMeta::default());
    let back = read(text.as_bytes(), format, tilt).expect("a written file must read back");
    let d2 = back.to_diagram().expect("a written file must expand");
    assert_eq!(d2.values(), d.values());
}
