//! Baselines: the samplers a user would pick instead of the HDS mapping, behind the same trait.
