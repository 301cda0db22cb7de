//! `gonio bench` — placeholder; the benchmarks are written on the `numbers` branch.

use crate::args::BenchArgs;

/// Runs the benchmarks described by `args`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let _ = args;
    anyhow::bail!("`gonio bench` is not yet implemented")
}
