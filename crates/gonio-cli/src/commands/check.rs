//! `gonio check`: the whole test battery on the chosen sampler.

use crate::args::CheckArgs;
use crate::load::{build_sampler, load};
use crate::progress::Progress;
use crate::settings::Settings;
use gonio::check::{cell_boundary_points, run_battery_with_progress, BatteryOptions};
use gonio::Sampler;

/// Runs `gonio check`; `Ok(true)` when every item passed.
pub fn run(a: &CheckArgs, settings: &Settings) -> anyhow::Result<bool> {
    let loaded = load(&a.input, settings)?;
    let mut opts = options(a)?;
    let sampler = build_sampler(a.method.diagram()?, &loaded)?;
    let refinement = sampler.refinement().cloned();
    // A method with a guaranteed bound (the HDS map) claims it; the flux check integrates the power
    // of the target the sampler normalises: the DATA's power for every method (the HDS map's target
    // is the data, zero outside its measured range), so a map that invents or drops light fails it.
    opts.ratio.claimed_bound = sampler.ratio_bound();
    // The round trip also runs on the preimages of the diagram's cell boundaries.
    opts.round_trip.extra_points = cell_boundary_points(
        sampler.as_ref(),
        &loaded.diagram,
        if a.quick { 16 } else { 64 },
    );
    report(
        &*sampler,
        opts,
        a,
        settings,
        refinement.as_ref(),
        "",
        serde_json::json!({}),
    )
}

/// The battery options of `a` (`--quick`, `--seed`, `--samples`).
pub fn options(a: &CheckArgs) -> anyhow::Result<BatteryOptions> {
    let mut opts = if a.quick {
        BatteryOptions::quick()
    } else {
        BatteryOptions::default()
    }
    .with_seed(a.seed);
    if let Some(n) = a.samples {
        anyhow::ensure!(n > 0, "--samples must be positive");
        opts.chi_square.samples = n;
        opts.flux.samples = n;
    }
    Ok(opts)
}

/// Runs the battery on `sampler` (its flux check against the sampler's target power) and prints
/// the report: `head` and the refinement line, then the report's text; with `--json` one object,
/// the report's keys with `extra`'s and the refinement's. `Ok(true)` when every item passed.
pub fn report(
    sampler: &dyn Sampler,
    mut opts: BatteryOptions,
    a: &CheckArgs,
    settings: &Settings,
    refinement: Option<&gonio::mapping::Refinement>,
    head: &str,
    extra: serde_json::Value,
) -> anyhow::Result<bool> {
    opts.flux_total = sampler.target_power();
    let progress = Progress::fraction("check", settings.quiet);
    let report =
        run_battery_with_progress(sampler, &opts, &|item, f| progress.set_fraction(f, item));
    drop(progress);
    let text = if a.json {
        let mut v = serde_json::to_value(&report)?;
        if let (Some(o), serde_json::Value::Object(e)) = (v.as_object_mut(), extra) {
            o.extend(e);
        }
        if let (Some(r), Some(o)) = (refinement, v.as_object_mut()) {
            o.insert("tolerance".into(), r.tolerance.into());
            o.insert(
                "refinement".into(),
                serde_json::json!({
                    "reached": r.reached,
                    "ratio_bound": [r.bound.0, r.bound.1],
                    "parallels_before": r.parallels_before,
                    "parallels_after": r.parallels_after,
                    "meridians_added": r.meridians_added,
                    "memory_bytes": r.memory_after,
                    "build_time_ms": r.build_seconds * 1e3,
                }),
            );
        }
        serde_json::to_string_pretty(&v)? + "\n"
    } else {
        let mut t = head.to_string();
        t += &match refinement {
            Some(r) => format!(
                "tolerance {} asked: pdf/target guaranteed within [{:.6}, {:.6}] ({}); {} → {} parallels, {} bytes, built in {:.3} ms\n",
                r.tolerance,
                r.bound.0,
                r.bound.1,
                if r.reached { "reached" } else { "NOT reached" },
                r.parallels_before,
                r.parallels_after,
                r.memory_after,
                r.build_seconds * 1e3
            ),
            None => String::new(),
        };
        t.push_str(&report.to_string());
        if !t.ends_with('\n') {
            t.push('\n');
        }
        t
    };
    crate::output::print(&text)?;
    Ok(report.passed)
}
