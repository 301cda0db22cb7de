//! `gonio convert IN OUT`: JSON ↔ IES LM-63-2019 ↔ EULUMDAT, chosen by OUT's extension; with
//! `--to pbrt-v4`, the image of pbrt-v4's goniometric light ([`super::pbrt`]).

use crate::args::{ConvertArgs, ConvertTarget};
use crate::load::load;
use crate::output::Output;
use gonio::photometry::{write_ies, write_ldt, WriteMeta};
use std::io::Write;

/// Runs `gonio convert`.
pub fn run(a: &ConvertArgs, settings: &crate::settings::Settings) -> anyhow::Result<()> {
    let ext = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let out_name = a.output.display().to_string();
    if a.to == Some(ConvertTarget::PbrtV4) {
        if crate::envmap_in::is_image_name(&a.input) {
            return crate::envmap_in::convert_pbrt(a, ext.as_deref(), &settings.env);
        }
        return super::pbrt::run(a, ext.as_deref(), settings);
    }
    // Check the output format before reading anything.
    match ext.as_deref() {
        Some("json" | "ies" | "ldt") => {}
        Some(e @ ("exr" | "pfm")) => {
            anyhow::bail!("{out_name}: `.{e}` is written by `--to pbrt-v4` (the pbrt-v4 goniometric light image)")
        }
        Some(e) => {
            anyhow::bail!("{out_name}: unknown output format `.{e}`; expected .json, .ies or .ldt")
        }
        None => anyhow::bail!(
            "{out_name}: the output name has no extension; expected .json, .ies or .ldt"
        ),
    }
    let loaded = load(&a.input, settings)?;
    let d = &loaded.diagram;
    let luminaire = std::path::Path::new(&a.input)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| a.input.clone());
    let meta = WriteMeta {
        luminaire,
        ..WriteMeta::default()
    };
    let text = match ext.as_deref() {
        Some("json") => serde_json::to_string_pretty(&d.to_json())? + "\n",
        Some("ies") => write_ies(d, &meta),
        _ => write_ldt(d, &meta),
    };
    let mut out = Output::create(Some(&a.output))?;
    out.write_all(text.as_bytes())?;
    out.finish()
}
