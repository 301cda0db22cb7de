//! `gonio info`: grid, power, memory, build time and ratio bound of the HDS map; for photometric
//! files every header field that matters and every warning.

use crate::args::InfoArgs;
use crate::load::{build_sampler_timed, load, InputKind, Loaded};
use gonio::photometry::Photometry;
use gonio::{Diagram, Domain, MapRef, Method, SphereMap};
use serde::Serialize;

/// Angle range of one axis.
#[derive(Debug, Clone, Serialize)]
pub struct Axis {
    /// Number of angles.
    pub count: usize,
    /// Smallest angle, degrees.
    pub min_deg: f64,
    /// Largest angle, degrees.
    pub max_deg: f64,
}

impl Axis {
    fn of(a: &[f64]) -> Self {
        Axis {
            count: a.len(),
            min_deg: a.iter().copied().fold(f64::INFINITY, f64::min),
            max_deg: a.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// The diagram's grid: N parallels (θ from +z) × M meridians (φ from +x toward +y).
#[derive(Debug, Clone, Serialize)]
pub struct Grid {
    /// Parallels θ, degrees.
    pub theta: Axis,
    /// Meridians φ, degrees.
    pub phi: Axis,
}

impl Grid {
    fn of(d: &Diagram) -> Self {
        let deg = |a: &[f64]| a.iter().map(|x| x.to_degrees()).collect::<Vec<_>>();
        Grid {
            theta: Axis::of(&deg(d.theta())),
            phi: Axis::of(&deg(d.phi())),
        }
    }
}

/// The HDS map built for the input.
#[derive(Debug, Clone, Serialize)]
pub struct MapInfo {
    /// `hemisphere` or `sphere`.
    pub domain: &'static str,
    /// The data's integral over the domain (zero outside its measured θ range), in diagram units ×
    /// sr (lumens for candela): the map's target power. `null` in JSON only if it exceeds f64
    /// (see `normalised_target_power` × `value_scale`).
    pub target_power: f64,
    /// The power of the completed diagram the map samples (data plus zero guard bands).
    pub completed_power: f64,
    /// completed_power / target_power, computed without overflow (within 1e-6 of 1).
    pub power_ratio: f64,
    /// The target power divided by the data's largest value (always finite).
    pub normalised_target_power: f64,
    /// The data's largest value.
    pub value_scale: f64,
    /// Probability of a sample outside the data's measured θ range (exact, ≤ ~2e-7).
    pub probability_outside_measured: f64,
    /// Zones without data that the map completed with zero light (warnings).
    pub completions: Vec<String>,
    /// Bytes of the map's tables ([`gonio::Sampler::memory_bytes`]).
    pub memory_bytes: usize,
    /// The paper's count of precomputed floats, M·N + 2M + 2, on the map's grid.
    pub paper_table_floats: usize,
    /// Wall-clock time of building the map, milliseconds.
    pub build_time_ms: f64,
    /// Guaranteed [min, max] of pdf / target_pdf.
    pub ratio_bound: [f64; 2],
    /// `--tolerance` asked (absent: the map was not refined).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// What refinement to the tolerance reached and cost (absent without `--tolerance`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refinement: Option<RefinementInfo>,
    /// Sphere (split layout): probability of the lower hemisphere; absent for the hemisphere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower_probability: Option<f64>,
}

/// The cost and outcome of refinement to `--tolerance` ([`gonio::mapping::Refinement`]).
#[derive(Debug, Clone, Serialize)]
pub struct RefinementInfo {
    /// Whether `ratio_bound` lies within [1 − tolerance, 1 + tolerance].
    pub reached: bool,
    /// Why refinement stopped early (absent when the tolerance was reached).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// Parallels of the completed grid(s) before and after refinement.
    pub parallels_before: usize,
    /// Parallels after refinement.
    pub parallels_after: usize,
    /// Meridians added (always 0: the φ direction needs none).
    pub meridians_added: usize,
    /// Bytes of the tables before refinement (`memory_bytes` is after).
    pub memory_bytes_before: usize,
}

impl RefinementInfo {
    fn of(r: &gonio::mapping::Refinement) -> Self {
        RefinementInfo {
            reached: r.reached,
            stopped: r.stop.map(|s| s.to_string()),
            parallels_before: r.parallels_before,
            parallels_after: r.parallels_after,
            meridians_added: r.meridians_added,
            memory_bytes_before: r.memory_before,
        }
    }
}

/// A warning of a photometric reader.
#[derive(Debug, Clone, Serialize)]
pub struct WarningInfo {
    /// 1-based line (0: the file as a whole).
    pub line: usize,
    /// 1-based column (0: unknown).
    pub column: usize,
    /// What was tolerated.
    pub message: String,
}

/// One lamp set.
#[derive(Debug, Clone, Serialize)]
pub struct LampInfo {
    /// Number of lamps (IES: negative means absolute photometry).
    pub count: i64,
    /// Flux of the set in lumens as the file states it (IES: lumens per lamp, −1 = absolute).
    pub flux_lm: f64,
    /// Description (type of lamp).
    pub description: String,
    /// Wattage.
    pub watts: f64,
}

/// What a photometric file says about itself.
#[derive(Debug, Clone, Serialize)]
pub struct PhotometryInfo {
    /// `IES LM-63` or `EULUMDAT`.
    pub format: String,
    /// e.g. `LM-63-2019`.
    pub version: String,
    /// `A`, `B` or `C`.
    pub photometric_type: String,
    /// Lamp sets (IES: one).
    pub lamps: Vec<LampInfo>,
    /// Lamp lumens stated by the file (sum over the sets; IES: lamps × lumens per lamp); absent
    /// for IES absolute photometry (lumens per lamp −1).
    pub lamp_lumens: Option<f64>,
    /// IES candela multiplier, EULUMDAT conversion factor.
    pub multiplier: f64,
    /// Factor applied to the stored values to get candela.
    pub intensity_scale: f64,
    /// TILT specification.
    pub tilt: String,
    /// Stored vertical angles (γ for type C, V for A/B), degrees.
    pub stored_vertical: Axis,
    /// Stored horizontal angles (C for type C, H for A/B), degrees.
    pub stored_horizontal: Axis,
    /// Symmetry and expansion rule.
    pub symmetry: String,
    /// Whether the distribution was resampled (types A and B).
    pub resampled: bool,
    /// Largest stored intensity, candela.
    pub max_intensity_cd: f64,
    /// Total flux, lumens (closed-form integral of the expanded diagram).
    pub flux_lm: f64,
    /// Every warning of the reader.
    pub warnings: Vec<WarningInfo>,
}

impl PhotometryInfo {
    fn of(p: &Photometry, flux_lm: f64) -> Self {
        let lamps: Vec<LampInfo> = p
            .lamp_sets
            .iter()
            .map(|l| LampInfo {
                count: l.count,
                flux_lm: l.flux_lm,
                description: l.description.clone(),
                watts: l.watts,
            })
            .collect();
        let (lamp_lumens, multiplier) = match (&p.ies, &p.ldt) {
            (Some(i), _) => (
                (i.lumens_per_lamp > 0.0).then_some(i.lumens_per_lamp * i.lamps as f64),
                i.multiplier,
            ),
            (None, Some(l)) => (
                Some(p.lamp_sets.iter().map(|s| s.flux_lm).sum()),
                l.conversion_factor,
            ),
            (None, None) => (None, 1.0),
        };
        PhotometryInfo {
            format: p.format.to_string(),
            version: p.version.to_string(),
            photometric_type: p.photometric_type.to_string(),
            lamps,
            lamp_lumens,
            multiplier,
            intensity_scale: p.intensity_scale,
            tilt: p.tilt.to_string(),
            stored_vertical: Axis::of(&p.vertical_angles_deg),
            stored_horizontal: Axis::of(&p.horizontal_angles_deg),
            symmetry: p.symmetry.to_string(),
            resampled: p.is_resampled(),
            max_intensity_cd: p.max_intensity_cd(),
            flux_lm,
            warnings: p
                .warnings
                .iter()
                .map(|w| WarningInfo {
                    line: w.line,
                    column: w.column,
                    message: w.message.clone(),
                })
                .collect(),
        }
    }
}

/// Everything `gonio info` reports; `--json` prints it with these key names.
#[derive(Debug, Clone, Serialize)]
pub struct Info {
    /// The input as named.
    pub input: String,
    /// `example`, `json`, `ies` or `ldt`.
    pub format: &'static str,
    /// Unit of the values: `cd` for photometric input and the example, `value` for JSON.
    pub unit: &'static str,
    /// The (expanded) diagram's grid.
    pub grid: Grid,
    /// Closed-form integral of the diagram over its grid ([`Diagram::integral`]), unit × sr
    /// (lumens for candela).
    pub diagram_integral: f64,
    /// The HDS map.
    pub map: MapInfo,
    /// Photometric files only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub photometry: Option<PhotometryInfo>,
    /// Environment maps only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub envmap: Option<crate::envmap_in::EnvInfo>,
}

/// Collects the information about `loaded`.
pub fn collect(loaded: &Loaded) -> anyhow::Result<Info> {
    let (sampler, took) = build_sampler_timed(Method::Hds, loaded)?;
    // What only the map has: the completed grid of a hemisphere map, the lower-hemisphere
    // probability of a sphere map.
    let (hemisphere, sphere) = match sampler.hds_map() {
        Some(MapRef::Hemisphere(m)) => (Some(m), None),
        Some(MapRef::Sphere(m)) => (None, Some(m)),
        None => (None, None),
    };
    // The target and completion figures of issue 9, which only the two maps report.
    macro_rules! map_only {
        ($f:ident) => {
            match (hemisphere, sphere) {
                (Some(m), _) => m.$f(),
                (_, Some(m)) => m.$f(),
                _ => anyhow::bail!("{}: the HDS sampler is neither map", loaded.name),
            }
        };
    }
    let paper = match hemisphere {
        Some(m) => m.paper_table_floats(),
        None => gonio::mapping::paper_table_floats(&loaded.diagram),
    };
    let (lo, hi) = sampler
        .ratio_bound()
        .expect("the HDS map has a guaranteed ratio bound");
    let integral = loaded.diagram.integral();
    Ok(Info {
        input: loaded.name.clone(),
        format: loaded.kind.name(),
        unit: if matches!(loaded.kind, InputKind::Json | InputKind::EnvMap) {
            "value"
        } else {
            "cd"
        },
        grid: Grid::of(&loaded.diagram),
        diagram_integral: integral,
        map: MapInfo {
            domain: match sampler.domain() {
                Domain::Hemisphere => "hemisphere",
                Domain::Sphere => "sphere",
            },
            target_power: sampler.target_power(),
            completed_power: map_only!(completed_power),
            power_ratio: map_only!(power_ratio),
            normalised_target_power: map_only!(normalised_target_power),
            value_scale: map_only!(value_scale),
            probability_outside_measured: map_only!(probability_outside_measured),
            completions: sampler
                .completions()
                .iter()
                .map(|c| c.to_string())
                .collect(),
            memory_bytes: sampler.memory_bytes(),
            paper_table_floats: paper,
            build_time_ms: took.as_secs_f64() * 1e3,
            ratio_bound: [lo, hi],
            tolerance: sampler.refinement().map(|r| r.tolerance),
            refinement: sampler.refinement().map(RefinementInfo::of),
            lower_probability: sphere.and_then(SphereMap::lower_probability),
        },
        photometry: loaded
            .photometry
            .as_deref()
            .map(|p| PhotometryInfo::of(p, integral)),
        envmap: loaded.envmap.as_deref().map(crate::envmap_in::EnvInfo::of),
    })
}

/// Runs `gonio info`.
pub fn run(a: &InfoArgs, settings: &crate::settings::Settings) -> anyhow::Result<()> {
    let loaded = load(&a.input, settings)?;
    let info = collect(&loaded)?;
    let text = if a.json {
        serde_json::to_string_pretty(&info)? + "\n"
    } else {
        human(&info)
            + &loaded
                .envmap
                .as_deref()
                .map(crate::envmap_in::info_lines)
                .unwrap_or_default()
    };
    crate::output::print(&text)
}

/// `1 meridian`, `3 parallels`.
fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// `IES LM-63-2002` (not `IES LM-63 LM-63-2002`), `EULUMDAT`: the format with its version, each
/// word once.
fn format_line(format: &str, version: &str) -> String {
    if version.is_empty() || format.ends_with(version) {
        format.to_string()
    } else if let Some(rest) = version.strip_prefix("LM-63") {
        match format.strip_suffix("LM-63") {
            Some(head) => format!("{head}LM-63{rest}"),
            None => format!("{format} {version}"),
        }
    } else {
        format!("{format} {version}")
    }
}

fn human(i: &Info) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let power_unit = if i.unit == "cd" { "lm" } else { "value·sr" };
    let g = &i.grid;
    let _ = writeln!(s, "input            {} ({})", i.input, i.format);
    let _ = writeln!(
        s,
        "grid             {} × {}; θ {}°..{}°, φ {}°..{}°",
        plural(g.theta.count, "parallel", "parallels"),
        plural(g.phi.count, "meridian", "meridians"),
        g.theta.min_deg,
        g.theta.max_deg,
        g.phi.min_deg,
        g.phi.max_deg
    );
    let m = &i.map;
    let _ = writeln!(s, "domain           {}", m.domain);
    let power = |p: f64, normalised: f64| {
        if p.is_finite() {
            format!("{p}")
        } else {
            format!("{normalised} × {} (beyond f64)", m.value_scale)
        }
    };
    let _ = writeln!(
        s,
        "total power      {} {power_unit} (map target = data), diagram integral {} {power_unit}",
        power(m.target_power, m.normalised_target_power),
        power(i.diagram_integral, m.normalised_target_power)
    );
    let _ = writeln!(
        s,
        "outside data     probability {:e} outside the measured θ range; map power / data = {}",
        m.probability_outside_measured, m.power_ratio
    );
    for c in &m.completions {
        let _ = writeln!(s, "  {}: warning: {c}", i.input);
    }
    let _ = writeln!(
        s,
        "table memory     {} bytes (paper's M·N+2M+2 = {} floats = {} bytes as f32)",
        m.memory_bytes,
        m.paper_table_floats,
        4 * m.paper_table_floats
    );
    let _ = writeln!(s, "build time       {:.3} ms", m.build_time_ms);
    let _ = writeln!(
        s,
        "pdf/target       within [{}, {}] (guaranteed)",
        m.ratio_bound[0], m.ratio_bound[1]
    );
    if let (Some(t), Some(r)) = (m.tolerance, &m.refinement) {
        let _ = writeln!(
            s,
            "tolerance        {t} asked: {}; {} parallels → {}, {} meridians added, {} → {} bytes",
            if r.reached {
                "reached".to_string()
            } else {
                format!(
                    "NOT reached ({})",
                    r.stopped.as_deref().unwrap_or("round-off")
                )
            },
            r.parallels_before,
            r.parallels_after,
            r.meridians_added,
            r.memory_bytes_before,
            m.memory_bytes
        );
    }
    if let Some(p) = m.lower_probability {
        let _ = writeln!(s, "lower hemisphere probability {p}");
    }
    if let Some(p) = &i.photometry {
        let _ = writeln!(s, "format           {}", format_line(&p.format, &p.version));
        let _ = writeln!(s, "photometric type {}", p.photometric_type);
        for l in &p.lamps {
            let _ = writeln!(
                s,
                "lamps            {} × {} lm, {} W, {}",
                l.count, l.flux_lm, l.watts, l.description
            );
        }
        match p.lamp_lumens {
            Some(l) => {
                let _ = writeln!(s, "lamp lumens      {l}");
            }
            None => {
                let _ = writeln!(s, "lamp lumens      absolute photometry");
            }
        }
        let _ = writeln!(
            s,
            "multiplier       {} (intensity scale {})",
            p.multiplier, p.intensity_scale
        );
        let _ = writeln!(s, "TILT             {}", p.tilt);
        let _ = writeln!(
            s,
            "stored angles    vertical {} ({}°..{}°), horizontal {} ({}°..{}°)",
            p.stored_vertical.count,
            p.stored_vertical.min_deg,
            p.stored_vertical.max_deg,
            p.stored_horizontal.count,
            p.stored_horizontal.min_deg,
            p.stored_horizontal.max_deg
        );
        let _ = writeln!(
            s,
            "expanded grid    {} × {}{}",
            g.theta.count,
            g.phi.count,
            if p.resampled { " (resampled)" } else { "" }
        );
        let _ = writeln!(s, "symmetry         {}", p.symmetry);
        let _ = writeln!(s, "max intensity    {} cd", p.max_intensity_cd);
        let _ = writeln!(s, "flux             {} lm", p.flux_lm);
        let _ = writeln!(s, "warnings         {}", p.warnings.len());
        for w in &p.warnings {
            let _ = writeln!(
                s,
                "  {}:{}:{}: warning: {}",
                i.input, w.line, w.column, w.message
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::{format_line, plural};

    #[test]
    fn wording() {
        assert_eq!(format_line("IES LM-63", "LM-63-2002"), "IES LM-63-2002");
        assert_eq!(format_line("EULUMDAT", "EULUMDAT"), "EULUMDAT");
        assert_eq!(plural(1, "meridian", "meridians"), "1 meridian");
        assert_eq!(plural(3, "parallel", "parallels"), "3 parallels");
    }
}
