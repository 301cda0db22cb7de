//! Points of the unit square: Halton (bases 2, 3), Owen-scrambled Sobol' in 2D, and seeded iid.
