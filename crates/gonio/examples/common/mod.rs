//! Helpers shared by the experiment examples: output paths, CSV / Markdown tables, timing, and a
//! tiny dependency-free SVG writer for log–log line plots.
#![allow(dead_code)]

pub mod profile;
pub mod room;

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// `docs/experiments/` of the workspace (created if missing).
pub fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/experiments");
    std::fs::create_dir_all(&dir).expect("create docs/experiments");
    dir
}

/// Whether `--quick` was passed on the command line.
pub fn quick() -> bool {
    std::env::args().any(|a| a == "--quick")
}

#[path = "../../tests/common/corpus.rs"]
mod corpus;
#[allow(unused_imports)]
pub use corpus::{corpus_dir, corpus_files, envmaps_dir};

/// The random `w` × `h` sky of the environment-map experiments (xorshift, values in [0, 4)).
pub fn random_sky(w: usize, h: usize) -> gonio::image::Image {
    let mut rgb = Vec::with_capacity(w * h * 3);
    let mut x = 0x9e3779b97f4a7c15u64;
    for _ in 0..w * h * 3 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        rgb.push((x >> 40) as f32 / (1u64 << 24) as f32 * 4.0);
    }
    gonio::image::Image::new(w, h, rgb).unwrap()
}

/// A simple table: a header and rows of already formatted cells.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new(header: &[&str]) -> Self {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }
    pub fn push(&mut self, row: Vec<String>) {
        assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }
    pub fn csv(&self) -> String {
        let mut s = self.header.join(",") + "\n";
        for r in &self.rows {
            s += &r.join(",");
            s.push('\n');
        }
        s
    }
    pub fn markdown(&self) -> String {
        let mut s = format!("| {} |\n", self.header.join(" | "));
        s += &format!("|{}\n", "---|".repeat(self.header.len()));
        for r in &self.rows {
            s += &format!("| {} |\n", r.join(" | "));
        }
        s
    }
    /// Writes `NAME.csv` and `NAME.md` into [`out_dir`] and prints the Markdown.
    pub fn save(&self, name: &str, title: &str) {
        let dir = out_dir();
        std::fs::write(dir.join(format!("{name}.csv")), self.csv()).expect("write csv");
        let md = format!("### {title}\n\n{}", self.markdown());
        std::fs::write(dir.join(format!("{name}.md")), &md).expect("write md");
        println!("{md}");
    }
}

/// Median of a slice (sorted copy).
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

pub use gonio::clock::thread_cpu_ns;

/// A stopwatch of the thread's CPU time where the OS reports it, else of wall time.
pub struct CpuClock {
    cpu: Option<u64>,
    wall: Instant,
}

impl CpuClock {
    /// Started now.
    pub fn start() -> Self {
        CpuClock {
            cpu: thread_cpu_ns(),
            wall: Instant::now(),
        }
    }

    /// Nanoseconds since the start.
    pub fn ns(&self) -> f64 {
        match (self.cpu, thread_cpu_ns()) {
            (Some(a), Some(b)) => (b - a) as f64,
            _ => self.wall.elapsed().as_nanos() as f64,
        }
    }
}

/// Median over `repeats` runs of `f` of the nanoseconds per item (`items` per run), measured in
/// the thread's CPU time where the OS reports it (so that time the thread spends descheduled on a
/// shared machine does not count), else in wall time.
pub fn ns_per_item(repeats: usize, items: usize, mut f: impl FnMut()) -> f64 {
    f(); // warm-up
    let t: Vec<f64> = (0..repeats)
        .map(|_| {
            let clock = CpuClock::start();
            f();
            clock.ns() / items as f64
        })
        .collect();
    median(&t)
}

/// One series of a plot.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub dashed: bool,
}

const COLOURS: [&str; 10] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];

/// Writes a log–log line plot as a self-contained SVG file into [`out_dir`].
pub fn loglog_svg(name: &str, title: &str, xlabel: &str, ylabel: &str, series: &[Series]) {
    let (w, h) = (720.0, 480.0);
    let (ml, mr, mt, mb) = (70.0, 190.0, 40.0, 55.0);
    let pts = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts {
        x0 = x0.min(x.log10());
        x1 = x1.max(x.log10());
        y0 = y0.min(y.log10());
        y1 = y1.max(y.log10());
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let (x0, x1, y0, y1) = (
        x0.floor(),
        x1.ceil().max(x0.floor() + 1.0),
        y0.floor(),
        y1.ceil().max(y0.floor() + 1.0),
    );
    let px = |x: f64| ml + (x.log10() - x0) / (x1 - x0) * (w - ml - mr);
    let py = |y: f64| mt + (y1 - y.log10()) / (y1 - y0) * (h - mt - mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="14">{}</text>"#,
        (ml + w - mr) / 2.0,
        esc(title)
    );
    // grid and tick labels at the decades
    for e in (x0 as i32)..=(x1 as i32) {
        let x = px(10f64.powi(e));
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle">1e{e}</text>"##,
            h - mb,
            h - mb + 16.0
        );
    }
    for e in (y0 as i32)..=(y1 as i32) {
        let y = py(10f64.powi(e));
        let _ = writeln!(
            s,
            r##"<line x1="{ml}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">1e{e}</text>"##,
            w - mr,
            ml - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r##"<rect x="{ml}" y="{mt}" width="{}" height="{}" fill="none" stroke="#000"/>"##,
        w - ml - mr,
        h - mt - mb
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (ml + w - mr) / 2.0,
        h - 12.0,
        esc(xlabel)
    );
    let _ = writeln!(
        s,
        r#"<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">{}</text>"#,
        (mt + h - mb) / 2.0,
        (mt + h - mb) / 2.0,
        esc(ylabel)
    );
    for (k, ser) in series.iter().enumerate() {
        let c = COLOURS[k % COLOURS.len()];
        let path: Vec<String> = ser
            .points
            .iter()
            .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite())
            .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
            .collect();
        let dash = if ser.dashed {
            r#" stroke-dasharray="6 4""#
        } else {
            ""
        };
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="1.8"{dash}/>"#,
            path.join(" ")
        );
        let ly = mt + 10.0 + 18.0 * k as f64;
        let lx = w - mr + 12.0;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="2"{dash}/><text x="{}" y="{}">{}</text>"#,
            lx + 24.0,
            lx + 30.0,
            ly + 4.0,
            esc(&ser.label)
        );
    }
    s += "</svg>\n";
    std::fs::write(out_dir().join(format!("{name}.svg")), s).expect("write svg");
}

fn esc(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Least-squares slope of log y against log x.
pub fn loglog_slope(points: &[(f64, f64)]) -> f64 {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    let n = p.len() as f64;
    let (sx, sy) = p.iter().fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = p.iter().fold((0.0, 0.0), |a, b| {
        (a.0 + (b.0 - mx) * (b.1 - my), a.1 + (b.0 - mx) * (b.0 - mx))
    });
    num / den
}

/// One line describing the machine: logical cores and the CPU model from /proc/cpuinfo.
pub fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    format!("{model}, {cores} logical cores available")
}

/// Parallel counts of the random diagram set (cycled).
pub const SET_N: [usize; 11] = [2, 3, 4, 5, 7, 10, 13, 19, 25, 31, 40];

/// One diagram of the random set.
pub struct SetDiagram {
    pub family: gonio::synthetic::Family,
    pub n: usize,
    pub m: usize,
    pub irregular: bool,
    pub diagram: gonio::Diagram,
}

/// The deterministic set of `count` random hemisphere diagrams of the experiments: the families
/// cycle through `Family::ALL`, N through [`SET_N`], regular and irregular grids alternate, and M
/// is drawn from 1–72 (1 for the rotational family).
pub fn diagram_set(count: usize) -> Vec<SetDiagram> {
    use gonio::synthetic::{random_hemisphere, Family};
    (0..count)
        .map(|k| {
            let family = Family::ALL[k % Family::ALL.len()];
            let n = SET_N[(k / Family::ALL.len()) % SET_N.len()];
            let irregular = (k / (Family::ALL.len() * SET_N.len())) % 2 == 1;
            // M from a cheap hash of k, 1..=72
            let h = (k as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40;
            let m = if family == Family::Rotational {
                1
            } else {
                1 + (h % 72) as usize
            };
            SetDiagram {
                family,
                n,
                m,
                irregular,
                diagram: random_hemisphere(family, n, m, irregular, 1000 + k as u64),
            }
        })
        .collect()
}
