use shader_core::rng::*;

/// PCG32 XSH-RR written with native u64, as in the reference implementation.
struct RefPcg {
    state: u64,
    inc: u64,
}

impl RefPcg {
    fn new(seed: u64, stream: u64) -> Self {
        let mut r = RefPcg { state: 0, inc: (stream << 1) | 1 };
        r.next();
        r.state = r.state.wrapping_add(seed);
        r.next();
        r
    }
    fn next(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(6364136223846793005).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }
}

#[test]
fn pcg32_matches_the_64_bit_reference() {
    for (seed, stream) in [(42u32, 54u32), (0, 0), (u32::MAX, u32::MAX), (12345, 0x8000_0001)] {
        let mut a = Pcg32::new(seed, stream);
        let mut b = RefPcg::new(u64::from(seed), u64::from(stream));
        for _ in 0..10_000 {
            assert_eq!(a.next_u32(), b.next());
        }
    }
}

#[test]
fn unit_floats_are_in_range_and_uniform() {
    let mut r = Pcg32::new(1, 2);
    let mut hist = [0u32; 16];
    for _ in 0..160_000 {
        let u = r.next_f32();
        assert!((0.0..1.0).contains(&u));
        hist[(u * 16.0) as usize] += 1;
    }
    for h in hist {
        assert!((9_500..10_500).contains(&h), "{hist:?}");
    }
    assert_eq!(u32_to_unit_f32(u32::MAX), 1.0 - 1.0 / 16_777_216.0);
}

#[test]
fn sobol_and_radical_inverse_first_points() {
    let ys: Vec<f32> = (0..8).map(|i| sobol_2d(i, 0, 0).1).collect();
    assert_eq!(ys, vec![0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]);
    let xs: Vec<f32> = (0..4).map(radical_inverse_base2).collect();
    assert_eq!(xs, vec![0.0, 0.5, 0.25, 0.75]);
    assert_eq!(reverse_bits(1), 1 << 31);
    for v in [0u32, 1, 0xdead_beef, u32::MAX, 0x1234_5678] {
        assert_eq!(reverse_bits(v), v.reverse_bits());
    }
}

#[test]
fn sobol_2d_is_stratified() {
    // Every 2^k-point prefix of the (0,2)-sequence puts exactly one point in each elementary
    // interval of area 1/2^k: check the 16 x 16 grid with 256 points has 1 point per cell row/col pair.
    for (nx, ny) in [(16usize, 16usize), (4, 64), (256, 1)] {
        let n = nx * ny;
        let mut seen = vec![0u32; n];
        for i in 0..n as u32 {
            let (x, y) = sobol_2d(i, 0, 0);
            seen[(y * ny as f32) as usize * nx + (x * nx as f32) as usize] += 1;
        }
        assert!(seen.iter().all(|&c| c == 1), "{nx}x{ny}");
    }
}

#[test]
fn r2_is_well_spread() {
    let mut cells = [0u32; 64];
    for i in 0..6400 {
        let (x, y) = r2(i, 0, 0);
        cells[(y * 8.0) as usize * 8 + (x * 8.0) as usize] += 1;
    }
    for c in cells {
        assert!((95..=105).contains(&c), "{cells:?}");
    }
}

/// Dimension 2 of Sobol from its direction numbers, one bit of the index at a time.
fn sobol_dim2_by_direction_numbers(i: u32) -> u32 {
    let (mut y, mut v, mut bits) = (0u32, 1u32 << 31, i);
    while bits != 0 {
        if bits & 1 != 0 {
            y ^= v;
        }
        v ^= v >> 1;
        bits >>= 1;
    }
    y
}

#[test]
fn sobol_dim2_transform_equals_direction_numbers() {
    let mut r = Pcg32::new(9, 9);
    let idx: Vec<u32> = (0..4096).chain([u32::MAX, 1 << 31, 0xdead_beef]).chain((0..4096).map(|_| r.next_u32())).collect();
    for i in idx {
        assert_eq!(reverse_bits(sobol_dim2_reversed(i)), sobol_dim2_by_direction_numbers(i), "index {i:#x}");
    }
}

/// Whether points `pts` (2^m of them) put exactly one point in every elementary interval
/// [a/2^k, (a+1)/2^k) x [b/2^(m-k), (b+1)/2^(m-k)), k = 0..=m: a (0, m, 2)-net in base 2.
fn is_0m2_net(pts: &[(f32, f32)]) -> bool {
    let m = pts.len().trailing_zeros();
    (0..=m).all(|k| {
        let (nx, ny) = (1usize << k, 1usize << (m - k));
        let mut seen = vec![0u32; pts.len()];
        for &(x, y) in pts {
            seen[(y * ny as f32) as usize * nx + (x * nx as f32) as usize] += 1;
        }
        seen.iter().all(|&c| c == 1)
    })
}

#[test]
fn owen_scrambled_sobol_prefixes_are_nets_for_every_seed() {
    for seed in [0u32, 1, 7, 0xdead_beef, 0x8000_0000, u32::MAX] {
        for m in [0u32, 1, 4, 8] {
            let pts: Vec<(f32, f32)> = (0..1u32 << m).map(|i| sobol_owen_2d(i, seed)).collect();
            assert!(is_0m2_net(&pts), "seed {seed:#x}, 2^{m} points");
            // The 1D sequence puts one point in each of 2^m intervals.
            let mut seen = vec![0u32; 1 << m];
            for i in 0..1u32 << m {
                seen[(sobol_owen_1d(i, seed) * (1u32 << m) as f32) as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "1D, seed {seed:#x}, 2^{m} points");
        }
        // A prefix that is not a power of two is still well spread, and the next block of 2^m is a net too.
        let pts: Vec<(f32, f32)> = (256..512).map(|i| sobol_owen_2d(i, seed)).collect();
        assert!(is_0m2_net(&pts), "seed {seed:#x}, points 256..512");
    }
}

#[test]
fn owen_scrambling_randomizes_each_point_uniformly() {
    // One index under many seeds: each coordinate uniform on [0, 1) (Owen 1995: every point of a
    // nested uniform scramble is uniformly distributed), and seeds give different sequences.
    let (mut hx, mut hy, mut h1) = ([0u32; 16], [0u32; 16], [0u32; 16]);
    for seed in 0..64_000u32 {
        let (x, y) = sobol_owen_2d(5, pcg_hash(seed));
        hx[(x * 16.0) as usize] += 1;
        hy[(y * 16.0) as usize] += 1;
        h1[(sobol_owen_1d(5, pcg_hash(seed)) * 16.0) as usize] += 1;
    }
    for h in [hx, hy, h1] {
        assert!(h.iter().all(|&c| (3_700..4_300).contains(&c)), "{h:?}");
    }
    assert_ne!(sobol_owen_2d(3, 1), sobol_owen_2d(3, 2));
    // The scramble is a bijection: distinct indices map to distinct values.
    let mut v: Vec<u32> = (0..65_536u32).map(|i| nested_uniform_scramble(i, 12_345)).collect();
    v.sort_unstable();
    v.dedup();
    assert_eq!(v.len(), 65_536);
}
