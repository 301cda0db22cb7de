//! The run's global options (`--quiet`, `--tolerance`, the environment-map options), parsed once
//! by `main` and handed to every command as a value: no command reads a global.

use crate::envmap_in::EnvCliOptions;

/// The global options of one run of the CLI.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Settings {
    /// `--quiet`: no progress bars (warnings are still printed).
    pub quiet: bool,
    /// `--tolerance`: the HDS map is refined until pdf / target lies in [1 − TOL, 1 + TOL].
    pub tolerance: Option<f64>,
    /// `--weight`, `--lookup`, `--mis-compensation`, as given.
    pub env: EnvCliOptions,
}
