//! Properties of the sequences for arbitrary seeds and indices.

use gonio::sequence::{Halton, Sequence, SequenceKind, Sobol};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn points_lie_in_the_half_open_square(seed: u64, start: u64, kind in 0usize..3) {
        let seq = Sequence::new(SequenceKind::ALL[kind], seed);
        let mut pts = [[0.0; 2]; 8];
        // Random jumps per 2^16 points; keep its start index moderate.
        let start = if kind == 2 { start % (1 << 24) } else { start };
        seq.fill(start, &mut pts);
        for p in pts {
            prop_assert!((0.0..1.0).contains(&p[0]) && (0.0..1.0).contains(&p[1]), "{:?}", p);
        }
        prop_assert_eq!(seq.point(start + 3), pts[3]);
    }

    #[test]
    fn scrambled_sobol_blocks_are_nets(seed: u64, block in 0u64..1000) {
        let m = 8;
        let mut pts = vec![[0.0; 2]; 1 << m];
        Sobol::owen(seed).fill(block << m, &mut pts);
        for a in 0..=m {
            let (na, nb) = (1usize << a, 1usize << (m - a));
            let mut cells = vec![0u8; 1 << m];
            for p in &pts {
                cells[(p[0] * na as f64) as usize * nb + (p[1] * nb as f64) as usize] += 1;
            }
            prop_assert!(cells.iter().all(|&c| c == 1), "a = {}", a);
        }
    }

    #[test]
    fn halton_skip_shifts(skip in 0u64..1 << 40, k in 0u64..1000) {
        prop_assert_eq!(Halton::with_skip(skip).point(k), Halton::new().point(skip + k));
    }
}
