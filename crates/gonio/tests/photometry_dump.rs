mod common;
use gonio::photometry::*;

#[test]
#[ignore]
fn dump() {
    let Some(dir) = common::corpus_dir() else { return };
    for sub in ["ies", "ldt"] {
        let mut files: Vec<_> = std::fs::read_dir(dir.join(sub)).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        for f in files {
            let bytes = std::fs::read(&f).unwrap();
            let fmt = FileFormat::from_path_extension(&f).unwrap();
            let name = f.file_name().unwrap().to_string_lossy().to_string();
            match read(&bytes, fmt, &NoTiltFiles) {
                Err(e) => println!("{name}: ERROR {e}"),
                Ok(p) => {
                    let d = p.to_diagram();
                    let lamp = p.lamp_sets.iter().map(|s| s.flux_lm * (s.count.signum() as f64).abs().max(1.0)).collect::<Vec<_>>();
                    let lorl = p.ldt.as_ref().map(|l| l.light_output_ratio_pct).unwrap_or(f64::NAN);
                    println!("{name}: {} {} type {} nv {} nh {} sym {:?} max {:.4} flux {:.3} lamps {:?} lorl {} scale {} diag {:?}",
                        p.format, p.version, p.photometric_type, p.vertical_angles_deg.len(), p.horizontal_angles_deg.len(), p.symmetry,
                        p.max_intensity_cd(), p.flux_lm(), lamp, lorl, p.intensity_scale,
                        d.as_ref().map(|d| (d.n_parallels(), d.n_meridians(), d.theta()[0].to_degrees(), d.theta()[d.n_parallels()-1].to_degrees())).map_err(|e| e.to_string()));
                    for w in &p.warnings { println!("    {w}"); }
                }
            }
        }
    }
}
