//! Writers: a [`Diagram`] in candela → IES LM-63-2019 or EULUMDAT text.
//!
//! Both writers store every meridian of the diagram as its own plane (no symmetry), with the
//! vertical angles γ = 180° − θ. Angles are written as the shortest decimal from which the readers
//! compute the stored radians exactly (`55`, not `54.999999999999986`), values in Rust's shortest
//! round-trip form (exponent form for extreme magnitudes), so that reading the text back gives
//! the same diagram bit for bit.

use crate::diagram::Diagram;
use std::fmt::Write as _;

/// Descriptive text written into the headers. [`WriteMeta::default`] fills every field with a
/// neutral placeholder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WriteMeta {
    /// IES `[TEST]` / EULUMDAT measurement report number.
    pub test: String,
    /// IES `[TESTLAB]` / EULUMDAT company identification.
    pub test_lab: String,
    /// IES `[ISSUEDATE]` / EULUMDAT date.
    pub issue_date: String,
    /// IES `[MANUFAC]`.
    pub manufacturer: String,
    /// IES `[LUMINAIRE]` / EULUMDAT luminaire name.
    pub luminaire: String,
}

impl Default for WriteMeta {
    fn default() -> Self {
        Self {
            test: "none".into(),
            test_lab: "gonio".into(),
            issue_date: "unknown".into(),
            manufacturer: "unknown".into(),
            luminaire: "goniometric diagram".into(),
        }
    }
}

/// A number in the shortest form that reads back to the same `f64` (exponent form for very
/// large or small magnitudes).
fn num(v: f64) -> String {
    crate::decimal::shortest(v)
}

/// One line per header field must not contain a line break.
fn one_line(s: &str) -> String {
    s.replace(['\r', '\n'], " ")
}

/// Writes `values` as lines of at most `per_line` numbers separated by spaces.
fn push_wrapped(out: &mut String, values: impl Iterator<Item = f64>, per_line: usize) {
    for (k, v) in values.enumerate() {
        if k > 0 {
            out.push(if k % per_line == 0 { '\n' } else { ' ' });
        }
        out.push_str(&num(v));
    }
    out.push('\n');
}

/// The vertical angles γ = 180° − θ in increasing order, and the parallel index of each: the
/// shortest decimal γ from which the readers compute θ = (180° − γ) in radians exactly as stored.
fn gammas(d: &Diagram) -> Vec<(f64, usize)> {
    let n = d.n_parallels();
    (0..n)
        .rev()
        .map(|j| {
            let t = d.theta()[j];
            let g = crate::decimal::shortest_preimage(180.0 - t.to_degrees(), |g| {
                (180.0 - g).to_radians().min(std::f64::consts::PI) == t
            });
            (g, j)
        })
        .collect()
}

/// The diagram as an IES LM-63-2019 file, type C, absolute photometry (lumens −1, multiplier 1,
/// values in candela), `TILT=NONE`, lines ending in CRLF. Every meridian φ_i becomes the horizontal
/// angle C = φ_i in degrees; with more than one meridian the closing plane C = φ_0 + 360° is added
/// (the standard 0–360° set when φ_0 = 0).
pub fn write_ies(d: &Diagram, meta: &WriteMeta) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "IES:LM-63-2019");
    let _ = writeln!(s, "[TEST] {}", one_line(&meta.test));
    let _ = writeln!(s, "[TESTLAB] {}", one_line(&meta.test_lab));
    let _ = writeln!(s, "[ISSUEDATE] {}", one_line(&meta.issue_date));
    let _ = writeln!(s, "[MANUFAC] {}", one_line(&meta.manufacturer));
    let _ = writeln!(s, "[LUMINAIRE] {}", one_line(&meta.luminaire));
    let _ = writeln!(
        s,
        "[FILEGENINFO] written by gonio from a goniometric diagram; absolute photometry in candela"
    );
    let _ = writeln!(s, "TILT=NONE");
    let g = gammas(d);
    let m = d.n_meridians();
    let mut horiz: Vec<(f64, usize)> = (0..m)
        .map(|i| (crate::decimal::degrees(d.phi()[i]), i))
        .collect();
    if m > 1 {
        horiz.push((horiz[0].0 + 360.0, 0));
    }
    let _ = writeln!(s, "1 -1 1 {} {} 1 2 0 0 0", g.len(), horiz.len());
    let _ = writeln!(s, "1 1.00001 0");
    push_wrapped(&mut s, g.iter().map(|x| x.0), 10);
    push_wrapped(&mut s, horiz.iter().map(|x| x.0), 10);
    for &(_, i) in &horiz {
        push_wrapped(&mut s, g.iter().map(|&(_, j)| d.value(i, j)), 10);
    }
    s.replace('\n', "\r\n")
}

/// The diagram as a EULUMDAT file: Isym 0 (every meridian stored as a C plane, angles as given),
/// one lamp set of 1000 lm and conversion factor 1, so that the stored cd/klm are the diagram's
/// candela unchanged. Dc (Dg) is the spacing when the meridians (parallels) are equidistant, else 0.
/// The direct ratios and the downward flux fraction are written as 0 and the light output ratio
/// as 100 %.
pub fn write_ldt(d: &Diagram, meta: &WriteMeta) -> String {
    let g = gammas(d);
    let m = d.n_meridians();
    let phi: Vec<f64> = d
        .phi()
        .iter()
        .map(|&p| crate::decimal::degrees(p))
        .collect();
    let spacing = |a: &[f64]| -> f64 {
        if a.len() < 2 {
            return 0.0;
        }
        let h = a[1] - a[0];
        if a.windows(2).all(|w| ((w[1] - w[0]) - h).abs() < 1e-9) {
            // The shortest decimal within the tolerance (15, not 14.999999999999998).
            crate::decimal::shortest_preimage(h, |x| (x - h).abs() < 1e-9)
        } else {
            0.0
        }
    };
    let gv: Vec<f64> = g.iter().map(|x| x.0).collect();
    let mut lines: Vec<String> = vec![
        one_line(&meta.test_lab),
        "3".into(),
        "0".into(),
        m.to_string(),
        num(spacing(&phi)),
        g.len().to_string(),
        num(spacing(&gv)),
        one_line(&meta.test),
        one_line(&meta.luminaire),
        "-".into(),
        "gonio.ldt".into(),
        one_line(&meta.issue_date),
    ];
    lines.extend(["0", "0", "0", "0", "0", "0", "0", "0", "0"].map(String::from));
    lines.extend(["0", "100", "1", "0", "1"].map(String::from)); // DFF, LORL, CFLI, tilt, sets
    lines.extend(["1", "unknown", "1000", "-", "-", "0"].map(String::from));
    lines.extend(std::iter::repeat_n("0".to_string(), 10));
    lines.extend(phi.iter().map(|&c| num(c)));
    lines.extend(gv.iter().map(|&x| num(x)));
    for i in 0..m {
        lines.extend(g.iter().map(|&(_, j)| num(d.value(i, j))));
    }
    let mut s = lines.join("\r\n");
    s.push_str("\r\n");
    s
}
