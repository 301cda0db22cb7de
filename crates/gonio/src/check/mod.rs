//! Checks: the statistical and numerical tests every sampler must pass.
