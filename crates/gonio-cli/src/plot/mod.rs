//! `gonio plot` — placeholder; the plot module is written on the `plot` branch.

use crate::args::PlotArgs;

/// Draws the plot described by `args`.
pub fn run(args: &PlotArgs) -> anyhow::Result<()> {
    let _ = args;
    anyhow::bail!("`gonio plot` is not yet implemented")
}
