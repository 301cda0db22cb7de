//! One module per subcommand; each exposes `run(&Args) -> anyhow::Result<()>` (check returns
//! whether every item passed).

pub mod brdf;
pub mod check;
pub mod convert;
pub mod directions;
pub mod info;
pub mod pbrt;
pub mod sample;
pub mod tables;
pub mod uv;
