use glam::Vec2;

use super::sobol::*;
use super::*;
use crate::lanes::{Lanes, MAX_LANES};

/// Lane `i` of a packet draws what sample `index + i` draws alone, for power-of-two and
/// other sample counts (whose permutations cycle-walk), on every lane type.
fn packet_draws_equal_the_pixel_draws<L: Lanes>() {
    let lane = |v: L, i: usize| {
        let mut out = [0.0; MAX_LANES];
        v.store(&mut out);
        out[i]
    };
    // (x, y, spp, seed), spp 0 for nested samples.
    let runs = [
        (0, 0, 16, 0),
        (7, 3, 48, 5),
        (1919, 1079, 256, 9),
        (5, 6, 0, 2),
    ];
    for (x, y, spp, seed) in runs {
        let samples = if spp == 0 { 64 } else { spp };
        for index in (0..samples).step_by(L::N) {
            let new_alone = |i| match spp {
                0 => PixelSampler::nested(x, y, i, seed),
                _ => PixelSampler::new(x, y, i, spp, seed),
            };
            let mut packet = match spp {
                0 => PacketSampler::<L>::nested(x, y, index, seed),
                _ => PacketSampler::<L>::new(x, y, index, spp, seed),
            };
            let (film, lens) = packet.get_camera();
            let vertices = [packet.get_vertex(), packet.get_vertex()];
            let mut branch = packet.branch(2);
            let (branch_lobes, branch_dirs) = branch.get_split_draws::<4>(3);
            let streams: Vec<_> = (0..L::N).map(|i| packet.lane(i)).collect();
            let after = packet.get_2d();
            for (i, stream) in streams.into_iter().enumerate() {
                let mut alone = new_alone(index + i as u32);
                let both = |v: [L; 2]| Vec2::new(lane(v[0], i), lane(v[1], i));
                let at = format!("pixel ({x}, {y}) sample {} of {spp}", index + i as u32);
                assert_eq!((both(film), both(lens)), alone.get_camera(), "{at}");
                for v in vertices {
                    let drawn = VertexSamples {
                        mix: lane(v.mix, i),
                        light_select: lane(v.light_select, i),
                        light: both(v.light),
                        lobe: lane(v.lobe, i),
                        bsdf: both(v.bsdf),
                        roulette: lane(v.roulette, i),
                    };
                    assert_eq!(drawn, alone.get_vertex(), "{at}");
                }
                let (lobes, dirs) = alone.branch(2).get_split_draws::<4>(3);
                for k in 0..4 {
                    assert_eq!(lane(branch_lobes[k], i), lobes[k], "{at}: split lobe {k}");
                    assert_eq!(both(branch_dirs[k]), dirs[k], "{at}: split direction {k}");
                }
                assert_eq!(stream.clone().get_2d(), alone.clone().get_2d(), "{at}");
                assert_eq!(both(after), alone.get_2d(), "{at}");
            }
        }
    }
}

#[test]
fn packets_draw_each_samples_own_values() {
    struct PacketDraws;
    impl crate::lanes::OnLanes for PacketDraws {
        type Output = ();
        fn run<L: Lanes>(&self) {
            packet_draws_equal_the_pixel_draws::<L>();
        }
    }
    crate::lanes::tests::on_every_lane_type(&PacketDraws);
}

/// After a vertex that used only its mix choice, the next draws are those that follow a
/// single `get_1d`.
#[test]
fn unread_vertex_dimensions_are_drawn_again() {
    let start = PixelSampler::new(3, 4, 5, 16, 9);
    let mut vertex = start.clone();
    let mix = vertex.get_vertex().mix;
    vertex.unread_after_mix();
    let mut one = start.clone();
    assert_eq!(mix, one.get_1d());
    assert_eq!(vertex.get_vertex(), one.get_vertex());
}

#[test]
fn permutation_masks_cover_the_range_with_the_fewest_bits() {
    for (len, mask) in [(0, 0), (1, 0), (2, 1), (3, 3), (7, 7), (64, 63), (65, 127)] {
        assert_eq!(permutation_mask(len), mask, "len {len}");
    }
    assert_eq!(permutation_mask(u32::MAX), u32::MAX);
}

#[test]
fn permutation_is_a_bijection() {
    for len in [1u32, 2, 7, 64, 100, 1000] {
        for p in [0u32, 1, 0xdead_beef] {
            let mut seen = vec![false; len as usize];
            for i in 0..len {
                let j = permutation_element(i, len, permutation_mask(len), p) as usize;
                assert!(!seen[j], "len {len} p {p}: {j} twice");
                seen[j] = true;
            }
        }
    }
}

/// The branch-free form equals the definition by direction numbers (the recurrence of
/// x + 1 from m_1 = 1: v1 = 1/2, v(k+1) = v(k) xor v(k)/2), the value the xor of the v(k)
/// of the index's set bits: the Pascal-triangle parity and `generator_columns` agree.
#[test]
fn sobol_dimension_1_matches_its_direction_numbers() {
    let columns = generator_columns(1, 0, [1, 0, 0]);
    let by_direction_numbers = |index: u32| generated(index, &columns);
    let mut state = 1u64;
    let indices = (0..4096u32).chain((0..4096).map(|_| {
        state = mix64(state);
        state as u32
    }));
    for index in indices.chain([u32::MAX]) {
        assert_eq!(
            sobol_dimension_1(index),
            by_direction_numbers(index),
            "index {index:#x}"
        );
    }
}

#[test]
fn samples_are_deterministic_and_in_range() {
    let draw = |x, y, i| {
        let mut s = PixelSampler::new(x, y, i, 64, 7);
        (s.get_2d(), s.get_1d(), s.get_2d())
    };
    assert_eq!(draw(3, 4, 5), draw(3, 4, 5));
    assert_ne!(draw(3, 4, 5), draw(4, 3, 5));
    for i in 0..64 {
        let (a, b, c) = draw(10, 20, i);
        for v in [a.x, a.y, b, c.x, c.y] {
            assert!((0.0..1.0).contains(&v));
        }
    }
}

/// Every 2D pair of a pixel's 64 samples puts exactly one sample in each cell of an 8x8
/// grid: the Sobol (0,2)-sequence property survives permutation and Owen scrambling.
#[test]
fn pixel_samples_are_stratified_in_each_2d_pair() {
    for pair in 0..4 {
        let mut cells = [0u32; 64];
        for i in 0..64 {
            let mut s = PixelSampler::new(5, 9, i, 64, 1);
            for _ in 0..pair {
                s.get_2d();
            }
            let u = s.get_2d();
            cells[(u.y * 8.0) as usize * 8 + (u.x * 8.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1), "pair {pair}: {cells:?}");
    }
}

/// The generator matrices' first columns are the direction integers the recurrence gives
/// by hand: 1, 3, 3, 9, 29 (x^2 + x + 1) and 1, 3, 1, 5, 31, 29 (x^3 + x + 1).
#[test]
fn sobol_dimensions_2_and_3_follow_their_recurrences() {
    let expect =
        |m: &[u32]| -> Vec<u32> { m.iter().enumerate().map(|(k, &m)| m << (31 - k)).collect() };
    assert_eq!(SOBOL_DIMENSION_2[..5], expect(&[1, 3, 3, 9, 29]));
    assert_eq!(SOBOL_DIMENSION_3[..6], expect(&[1, 3, 1, 5, 31, 29]));
    // Column k ends at fraction bit k (odd direction integers): the matrix is triangular
    // with a full diagonal, so each 2^k points take each of 2^k values once.
    for columns in [SOBOL_DIMENSION_2, SOBOL_DIMENSION_3] {
        for (k, c) in columns.iter().enumerate() {
            assert_eq!(c.trailing_zeros() as usize, 31 - k, "{columns:x?}");
        }
    }
    assert_eq!(generated(0b101, &SOBOL_DIMENSION_2), (1 << 31) ^ (3 << 29));
}

/// The camera's draw: its film position is `get_2d`'s; 16 samples of a pixel put one point
/// in each of the 16 cells halving all four coordinates (two padded pairs do not), and 16,
/// 64 or 256 put one in each cell of the square grids pairing the lens's first coordinate
/// with either film coordinate; for a uniform pixel and the prefixes an adaptive render
/// may stop at.
#[test]
fn camera_samples_stratify_film_and_lens_together() {
    let sampler = |nested: bool, i: u32, n: u32| {
        if nested {
            PixelSampler::nested(3, 4, i, 11)
        } else {
            PixelSampler::new(3, 4, i, n, 11)
        }
    };
    let one_per_cell = |points: &[[f32; 4]], cells_per_axis: [u32; 4]| {
        let mut seen = std::collections::HashSet::new();
        points.iter().all(|p| {
            seen.insert(std::array::from_fn::<u32, 4, _>(|k| {
                (p[k] * cells_per_axis[k] as f32) as u32
            }))
        })
    };
    for nested in [true, false] {
        for (n, side) in [(16u32, 4u32), (64, 8), (256, 16)] {
            let points: Vec<[f32; 4]> = (0..n)
                .map(|i| {
                    let (film, lens) = sampler(nested, i, n).get_camera();
                    assert_eq!(film, sampler(nested, i, n).get_2d());
                    [film.x, film.y, lens.x, lens.y]
                })
                .collect();
            assert!(
                one_per_cell(&points, [side, 1, side, 1]),
                "{n}: film x, lens x"
            );
            assert!(
                one_per_cell(&points, [1, side, side, 1]),
                "{n}: film y, lens x"
            );
            if n == 16 {
                assert!(one_per_cell(&points, [2; 4]), "nested {nested}: 4D");
                let padded: Vec<[f32; 4]> = (0..n)
                    .map(|i| {
                        let mut s = sampler(nested, i, n);
                        let (film, lens) = (s.get_2d(), s.get_2d());
                        [film.x, film.y, lens.x, lens.y]
                    })
                    .collect();
                assert!(!one_per_cell(&padded, [2; 4]));
            }
        }
    }
}

/// Every prefix of a nested pixel's samples that an adaptive render may stop at (16, 32,
/// 64, 128, 256) puts one sample in each elementary interval of its size in every 2D pair:
/// checked on the square grids (4x4, 8x8, 16x16) and the 2:1 ones (8x4, 16x8).
#[test]
fn nested_prefixes_are_stratified_in_each_2d_pair() {
    for (n, cols, rows) in [
        (16u32, 4u32, 4u32),
        (32, 8, 4),
        (64, 8, 8),
        (128, 16, 8),
        (256, 16, 16),
    ] {
        for pair in 0..3 {
            let mut cells = vec![0u32; n as usize];
            for i in 0..n {
                let mut s = PixelSampler::nested(3, 4, i, 11);
                for _ in 0..pair {
                    s.get_2d();
                }
                let u = s.get_2d();
                let cell = (u.y * rows as f32) as u32 * cols + (u.x * cols as f32) as u32;
                cells[cell as usize] += 1;
            }
            assert!(
                cells.iter().all(|&c| c == 1),
                "n {n} pair {pair}: {cells:?}"
            );
        }
    }
}

/// A split draw's values: each sample's eight are stratified among themselves, and all of
/// a pixel's 16 x 8 together, as 128 samples of a 2D pair (or a 1D dimension) would be.
#[test]
fn split_draws_are_stratified_alone_and_together() {
    const N: usize = 8;
    let spp = 16;
    let (mut all_2d, mut all_1d) = ([0u32; 128], [0u32; 128]);
    for i in 0..spp {
        let mut s = PixelSampler::new(5, 9, i, spp, 3);
        s.get_2d();
        let (values, points) = s.get_split_draws::<N>(N);
        let (mut own_2d, mut own_1d) = ([0u32; N], [0u32; N]);
        for (v, u) in values.into_iter().zip(points) {
            own_1d[(v * 8.0) as usize] += 1;
            own_2d[(u.y * 2.0) as usize * 4 + (u.x * 4.0) as usize] += 1;
            all_1d[(v * 128.0) as usize] += 1;
            all_2d[(u.y * 8.0) as usize * 16 + (u.x * 16.0) as usize] += 1;
        }
        assert!(own_1d.iter().chain(&own_2d).all(|&c| c == 1), "sample {i}");
    }
    assert!(all_1d.iter().chain(&all_2d).all(|&c| c == 1));
}

/// A draw of 2 of at most 4 (a path branching in two): each sample's two values lie in
/// the two halves, a pixel's 16 x 2 together one in each 32nd (and each 8x4 cell of the
/// square for the directions), and the values past the two are zero.
#[test]
fn split_draws_of_fewer_than_their_most_are_stratified() {
    let (mut all_1d, mut all_2d) = ([0u32; 32], [0u32; 32]);
    for i in 0..16 {
        let (values, points) = PixelSampler::new(3, 4, i, 16, 7).get_split_draws::<4>(2);
        assert_eq!(values[2..], [0.0; 2]);
        assert_eq!(points[2..], [Vec2::ZERO; 2]);
        assert_ne!(
            (values[0] * 2.0) as u32,
            (values[1] * 2.0) as u32,
            "sample {i}"
        );
        for (v, u) in values[..2].iter().zip(&points[..2]) {
            all_1d[(v * 32.0) as usize] += 1;
            all_2d[(u.y * 4.0) as usize * 8 + (u.x * 8.0) as usize] += 1;
        }
    }
    assert_eq!(all_1d, [1; 32]);
    assert_eq!(all_2d, [1; 32]);
}

/// A branch's stream is the same for the same branch, differs from the path's own and from
/// another branch's in every dimension, and is stratified over a pixel's samples.
#[test]
fn branch_streams_are_their_own() {
    let sampler = PixelSampler::new(3, 4, 5, 16, 7);
    let draw = |mut s: PixelSampler| [s.get_1d(), s.get_2d().x, s.get_2d().y, s.get_1d()];
    assert_eq!(draw(sampler.branch(1)), draw(sampler.branch(1)));
    let (own, one, two) = (
        draw(sampler.clone()),
        draw(sampler.branch(1)),
        draw(sampler.branch(2)),
    );
    for d in 0..4 {
        assert!(
            own[d] != one[d] && one[d] != two[d] && own[d] != two[d],
            "{d}"
        );
    }
    let mut strata = [0; 16];
    for i in 0..16 {
        let mut branch = PixelSampler::new(3, 4, i, 16, 7).branch(1);
        branch.get_1d();
        strata[(branch.get_1d() * 16.0) as usize] += 1;
    }
    assert_eq!(strata, [1; 16]);
}

/// Integrating a smooth function with 256 stratified samples beats independent random
/// sampling's expected error by a wide margin.
#[test]
fn stratified_estimate_is_accurate() {
    let f = |u: Vec2| libm::sinf(u.x * 3.0) * libm::cosf(u.y * 2.0) + u.x * u.y;
    let exact = (1.0 - libm::cosf(3f32)) / 3.0 * (libm::sinf(2f32) / 2.0) + 0.25;
    let n = 256;
    let mean: f32 = (0..n)
        .map(|i| f(PixelSampler::new(1, 2, i, n, 3).get_2d()))
        .sum::<f32>()
        / n as f32;
    // Independent sampling would have a standard error of about 0.02 here.
    assert!((mean - exact).abs() < 2e-3, "{mean} vs {exact}");
}
