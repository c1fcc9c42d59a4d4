//! The procedural textures: values at fixed points against LuxRender 1.x's own code (the
//! reference numbers were printed by its `core/texture.cpp` noise, fBm and turbulence and its
//! marble, dots and brick formulas compiled unchanged), value ranges and means over a domain,
//! exact values of the piecewise textures, and the 3D mapping's scale, rotate and translate.

use glam::{Vec2, Vec3};

use super::*;
use crate::assets::MemorySource;
use crate::parse::parse_scene;

/// The textures of a scene whose world holds `statements`, ready to evaluate, with their
/// names.
fn textures(statements: &str) -> (Textures, Vec<String>) {
    let mut source = MemorySource::new();
    let text = format!("Camera \"perspective\"\nWorldBegin\n{statements}\nWorldEnd\n");
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let names = desc.textures.iter().map(|t| t.name.clone()).collect();
    (Textures::new(&desc.textures, &source).unwrap(), names)
}

/// The value of the texture called `name` at world (= object) position `p` and uv `uv`.
fn eval_at(t: &(Textures, Vec<String>), name: &str, p: Vec3, uv: Vec2) -> Vec3 {
    let id =
        t.1.iter()
            .rposition(|n| n == name)
            .expect("texture defined");
    t.0.eval(
        ConstOrTexture::Texture(TextureId(id as u32)),
        &LookupPoint::new(p, uv),
    )
}

fn value(t: &(Textures, Vec<String>), name: &str, p: Vec3) -> f32 {
    eval_at(t, name, p, Vec2::ZERO).x
}

/// Points of a fixed, well-spread sequence in [lo, hi]^3 (a 3D Halton-like lattice).
fn points(n: usize, lo: f32, hi: f32) -> impl Iterator<Item = Vec3> {
    (0..n).map(move |i| {
        let f = |k: f32| (i as f32 * k).fract();
        lo + (hi - lo) * Vec3::new(f(0.618_034), f(0.754_877_7), f(0.569_840_3))
    })
}

/// Relative closeness for values computed with a different association of the same
/// arithmetic.
fn near(a: f32, b: f32) -> bool {
    (a - b).abs() <= 2e-5 * (1.0 + b.abs())
}

const REFERENCE_POINTS: [Vec3; 4] = [
    Vec3::new(0.3, 0.7, -1.2),
    Vec3::new(12.25, -3.5, 0.125),
    Vec3::new(-7.9, 100.3, 2.2),
    Vec3::new(0.5, 0.5, 0.5),
];

#[test]
fn noise_sums_and_marble_match_luxrender_at_fixed_points() {
    // Columns: noise, fbm(8 octaves, omega 0.5), turbulence (same), fbm(3, 0.7), windy,
    // marble's red channel (defaults), as LuxRender 1.x computes them.
    let reference: [[f32; 6]; 4] = [
        [
            0.574_470_9,
            0.334_738_34,
            0.857_778_7,
            0.236_165_85,
            0.058_011_975,
            0.859_488_7,
        ],
        [
            -0.080_628_22,
            -0.097_249_37,
            0.400_612_35,
            -0.091_964_945,
            -0.023_715_762,
            0.890_684_7,
        ],
        [
            0.314_955_95,
            0.301_802_28,
            0.422_378_06,
            0.282_721_85,
            0.081_769_8,
            0.835_214_1,
        ],
        [
            -0.125,
            -0.118_037_57,
            0.187_650_77,
            -0.137_513_22,
            -0.030_882_87,
            0.847_064_3,
        ],
    ];
    let t = textures(
        "Texture \"f\" \"float\" \"fbm\"\n\
         Texture \"w\" \"float\" \"wrinkled\"\n\
         Texture \"f3\" \"float\" \"fbm\" \"integer octaves\" 3 \"float roughness\" 0.7\n\
         Texture \"wind\" \"float\" \"windy\"\n\
         Texture \"m\" \"color\" \"marble\"",
    );
    for (p, r) in REFERENCE_POINTS.iter().zip(reference) {
        let got = [
            noise::noise(*p),
            value(&t, "f", *p),
            value(&t, "w", *p),
            value(&t, "f3", *p),
            value(&t, "wind", *p),
            value(&t, "m", *p),
        ];
        for (g, r) in got.iter().zip(r) {
            assert!(near(*g, r), "at {p}: {got:?} vs LuxRender {r}");
        }
    }
}

#[test]
fn dots_and_running_bricks_land_where_luxrender_puts_them() {
    // LuxRender's dots over a 200 x 200 grid of (s, t) in [-5, 5): how many are inside, and a
    // hash of the whole pattern.
    let mut count = 0;
    let mut hash = 0u64;
    for i in 0..200 {
        for j in 0..200 {
            let inside = dots::Dots::inside(i as f32 * 0.05 - 5.0, j as f32 * 0.05 - 5.0);
            count += inside as u32;
            hash = hash.wrapping_mul(31).wrapping_add(inside as u64);
        }
    }
    assert_eq!((count, hash), (6655, 285_947_411_889_816_093));

    // The default running bond on the plane y = 0.2: brick or mortar, and which brick.
    let t = textures("Texture \"b\" \"float\" \"brick\"");
    let TextureKind::Brick(brick) = &t.0.textures[0].kind else {
        panic!("a brick texture")
    };
    let (mut count, mut hash) = (0, 0u64);
    for i in 0..100 {
        for k in 0..100 {
            let p = Vec3::new(i as f32 * 0.0137 - 0.5, 0.2, k as f32 * 0.0091 - 0.3);
            let code = match brick.brick_at(p) {
                Some(index) => {
                    count += 1;
                    (index.x * 7.0 + index.y * 13.0 + index.z * 17.0 + 1000.0) as i32 as u64
                }
                None => 0,
            };
            hash = hash.wrapping_mul(31).wrapping_add(code);
        }
    }
    assert_eq!((count, hash), (8825, 16_633_866_070_429_827_214));
}

#[test]
fn perlin_noise_is_zero_on_the_lattice_continuous_and_centred() {
    for p in points(50, -40.0, 40.0) {
        assert_eq!(noise::noise(p.floor()), 0.0, "lattice point {}", p.floor());
    }
    // Continuity: the gradient of the noise is bounded (by about 2 per unit), so a step of
    // 1e-3 changes it by at most a few thousandths, also across cell faces.
    let mut max_step = 0.0f32;
    for p in points(2000, -10.0, 10.0) {
        for d in [Vec3::X, Vec3::Y, Vec3::Z] {
            let q = (p * 4.0).round() / 4.0 - 0.5e-3 * d;
            max_step = max_step.max((noise::noise(q + 1e-3 * d) - noise::noise(q)).abs());
        }
    }
    assert!(max_step < 4e-3, "largest change over 1e-3: {max_step}");
    // Mean 0 and a bounded range over a large domain.
    let values: Vec<f32> = points(20000, -50.0, 50.0).map(noise::noise).collect();
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    let (lo, hi) = values
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(mean.abs() < 0.01, "mean {mean}");
    assert!(
        lo > -1.05 && hi < 1.05 && lo < -0.6 && hi > 0.6,
        "range [{lo}, {hi}]"
    );
    // Not finite: 0, never a panic.
    assert_eq!(noise::noise(Vec3::new(f32::NAN, 0.0, 1.0)), 0.0);
    assert_eq!(noise::noise(Vec3::splat(f32::INFINITY)), 0.0);
}

#[test]
fn noise_textures_have_their_ranges_and_means() {
    let t = textures(
        "Texture \"f\" \"float\" \"fbm\"\n\
         Texture \"w\" \"float\" \"wrinkled\"\n\
         Texture \"wind\" \"float\" \"windy\"\n\
         Texture \"m\" \"color\" \"marble\" \"float scale\" 3 \"vector scale\" [2 2 2]",
    );
    let stats = |name: &str| {
        let v: Vec<f32> = points(20000, -30.0, 30.0)
            .map(|p| value(&t, name, p))
            .collect();
        let mean = v.iter().sum::<f32>() / v.len() as f32;
        let lo = v.iter().copied().fold(f32::MAX, f32::min);
        let hi = v.iter().copied().fold(f32::MIN, f32::max);
        (mean, lo, hi)
    };
    let (mean, lo, hi) = stats("f");
    assert!(
        mean.abs() < 0.01 && lo < -0.5 && hi > 0.5 && lo > -2.0 && hi < 2.0,
        "fbm {mean} [{lo}, {hi}]"
    );
    // Turbulence sums |noise| (mean about 0.2 per unit amplitude, 1 + 0.5 + ... ~ 2).
    let (mean, lo, hi) = stats("w");
    assert!(
        lo >= 0.0 && (0.3..0.6).contains(&mean) && hi < 2.0,
        "wrinkled {mean} [{lo}, {hi}]"
    );
    let (mean, lo, hi) = stats("wind");
    assert!(
        mean.abs() < 0.01 && lo > -1.0 && hi < 1.0 && hi > 0.1,
        "windy {mean} [{lo}, {hi}]"
    );
    // Marble stays inside its palette's hull times 1.5, and uses both ends of it.
    let mut lo = Vec3::splat(f32::MAX);
    let mut hi = Vec3::splat(f32::MIN);
    for p in points(20000, -30.0, 30.0) {
        let c = eval_at(&t, "m", p, Vec2::ZERO);
        lo = lo.min(c);
        hi = hi.max(c);
    }
    assert!(
        lo.cmpge(Vec3::splat(0.3)).all() && hi.cmple(Vec3::splat(0.9 + 1e-5)).all(),
        "marble [{lo}, {hi}]"
    );
    assert!(
        lo.x < 0.45 && hi.x > 0.85,
        "marble uses its dark vein and its light grey: [{lo}, {hi}]"
    );
}

#[test]
fn evaluation_is_deterministic() {
    // Two scenes parsed and built apart (as on two workers) give the same bits everywhere.
    let statement = "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 12";
    let (a, b) = (textures(statement), textures(statement));
    for p in points(100, -5.0, 5.0) {
        assert_eq!(value(&a, "f", p).to_bits(), value(&b, "f", p).to_bits());
    }
}

#[test]
fn vector_scale_rotate_translate_move_the_pattern_exactly() {
    let t = textures(
        "Texture \"plain\" \"float\" \"fbm\"\n\
         Texture \"moved\" \"float\" \"fbm\" \"vector translate\" [1 -2 0.5]\n\
         Texture \"scaled\" \"float\" \"fbm\" \"vector scale\" [2 4 0.5]\n\
         Texture \"turned\" \"float\" \"fbm\" \"vector rotate\" [0 0 90]\n\
         AttributeBegin\nTranslate 3 0 0\nTexture \"placed\" \"float\" \"fbm\"\nAttributeEnd",
    );
    for p in points(200, -3.0, 3.0) {
        let plain = value(&t, "plain", p);
        // Translated by t: the pattern at p + t is the plain one at p.
        let moved = value(&t, "moved", p + Vec3::new(1.0, -2.0, 0.5));
        assert!(near(moved, plain), "translate at {p}: {moved} vs {plain}");
        // Scaled by s: the pattern at s p is the plain one at p.
        let scaled = value(&t, "scaled", p * Vec3::new(2.0, 4.0, 0.5));
        assert!(near(scaled, plain), "scale at {p}: {scaled} vs {plain}");
        // Rotated 90 degrees about z (LuxRender applies the rotation to the point): the
        // pattern at p is the plain one at Rz(90) p = (-y, x, z).
        let turned = value(&t, "turned", p);
        let expected = value(&t, "plain", Vec3::new(-p.y, p.x, p.z));
        assert!(
            near(turned, expected),
            "rotate at {p}: {turned} vs {expected}"
        );
        // The transform at the Texture statement moves the pattern too, the opposite way to
        // `vector translate`: LuxRender 1.x's 3D mapping applies the CTM itself to the point.
        let placed = value(&t, "placed", p - Vec3::new(3.0, 0.0, 0.0));
        assert!(near(placed, plain), "CTM at {p}: {placed} vs {plain}");
    }
}

#[test]
fn rotated_running_bricks_on_a_floor_follow_luxrenders_mapping() {
    // procedural.lxs's floor: the default running bond (0.3 x 0.15 x 0.1, mortar 0.01, run
    // 0.75, offset -0.5 in y) with "vector rotate" [90 0 0] on the plane z = -0.5. LuxRender
    // maps world (x, y, z) through RotateX(90) to (x, -z, y) = (x, 0.5, y), adds 0.011 and
    // divides by the brick size: (0.1, 0.2) -> (0.37, 2.9067, 2.11), course 2, in-brick
    // fractions x 0.87, y 0.4067, z 0.11, all past the mortar (0.033, 0.067, 0.1): brick.
    let t = textures(
        "Texture \"f\" \"color\" \"brick\" \"color bricktex\" [0.45 0.22 0.15] \
         \"color mortartex\" [0.6 0.6 0.58] \"vector rotate\" [90 0 0]",
    );
    let (brick, mortar) = (Vec3::new(0.45, 0.22, 0.15), Vec3::new(0.6, 0.6, 0.58));
    let at = |x: f32, y: f32| eval_at(&t, "f", Vec3::new(x, y, -0.5), Vec2::ZERO);
    assert_eq!(at(0.1, 0.2), brick);
    // y 0.295: z fraction (0.306 - 3) 0.06 < 0.1, a bed joint.
    assert_eq!(at(0.1, 0.295), mortar);
    // x 0.1405 in course 2: x fraction (0.505 + 1.5 - 2) 0.005 < 0.033, a head joint.
    assert_eq!(at(0.1405, 0.2), mortar);
    // The depth coordinate 0.5 lies inside a brick in all four courses of the run's cycle
    // (y fractions 0.907, 0.157, 0.407, 0.657), so every course shows bricks.
    for course in 0..4 {
        assert_eq!(
            at(0.1, 0.05 + 0.1 * course as f32),
            brick,
            "course {course}"
        );
    }
}

#[test]
fn local_and_uv_coordinates_read_the_object_position_and_the_uv() {
    let t = textures(
        "Texture \"global\" \"float\" \"fbm\"\n\
         Texture \"local\" \"float\" \"fbm\" \"string coordinates\" \"local\"\n\
         Texture \"uv\" \"float\" \"fbm\" \"string coordinates\" \"uv\"",
    );
    let id = |name: &str| {
        ConstOrTexture::Texture(TextureId(t.1.iter().position(|n| n == name).unwrap() as u32))
    };
    let at = LookupPoint {
        p: Vec3::new(0.3, 0.7, -1.2),
        p_world: Vec3::new(12.25, -3.5, 0.125),
        uv: Vec2::new(-7.9, 100.3),
        prim: 0,
    };
    // The splat of a float texture (mean of three equal channels) may round the last bit.
    let check = |name: &str, p: Vec3| {
        let (got, expected) = (t.0.eval(id(name), &at).x, noise::fbm(p, 0.5, 8));
        assert!((got - expected).abs() < 1e-6, "{name}: {got} vs {expected}");
    };
    check("global", at.p_world);
    check("local", at.p);
    check("uv", at.uv.extend(0.0));
    assert!((noise::fbm(at.p_world, 0.5, 8) - noise::fbm(at.p, 0.5, 8)).abs() > 0.1);
}

#[test]
fn piecewise_textures_are_exact_at_known_points() {
    let t = textures(
        "Texture \"band\" \"color\" \"band\" \"float offsets\" [0 0.5 1] \"color tex1\" [1 0 0] \
           \"color tex2\" [0 1 0] \"color tex3\" [0 0 1] \"float amount\" 0.25\n\
         Texture \"amt\" \"float\" \"uv\"\n\
         Texture \"band2\" \"color\" \"band\" \"float offsets\" [0.2 0.6] \"color tex1\" [1 1 1] \
           \"color tex2\" [0 0 0] \"texture amount\" \"amt\"\n\
         Texture \"bilerp\" \"color\" \"bilerp\" \"color v00\" [1 0 0] \"color v01\" [0 1 0] \
           \"color v10\" [0 0 1] \"color v11\" [1 1 1]\n\
         Texture \"uvc\" \"color\" \"uv\" \"float uscale\" 2\n\
         Texture \"sum\" \"color\" \"add\" \"color tex1\" [0.25 0.5 1] \"texture tex2\" \"uvc\"\n\
         Texture \"diff\" \"float\" \"subtract\" \"float tex2\" 0.25\n\
         Texture \"dots\" \"float\" \"dots\" \"float inside\" 3 \"float outside\" -1",
    );
    let at = |name: &str, u: f32, v: f32| eval_at(&t, name, Vec3::ZERO, Vec2::new(u, v));
    assert_eq!(at("band", 0.0, 0.0), Vec3::new(0.5, 0.5, 0.0));
    // amount from the uv texture read as a float: (frac(u) + frac(v) + 0) / 3.
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-5;
    assert_eq!(at("band2", 0.3, 0.0), Vec3::ONE); // 0.1: below the first offset
    assert!(close(at("band2", 0.6, 0.6), Vec3::splat(0.5))); // 0.4: halfway
    assert!(close(at("band2", 0.3, 0.6), Vec3::splat(0.75))); // 0.3: a quarter of the way
    assert_eq!(at("band2", 0.95, 0.95), Vec3::ZERO); // 0.63: past the last offset
    assert_eq!(at("bilerp", 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(at("bilerp", 2.0, 1.0), Vec3::new(1.0, 0.0, 0.0)); // repeats per unit cell
    assert_eq!(at("bilerp", 0.5, 0.5), Vec3::new(0.5, 0.5, 0.5));
    assert_eq!(at("bilerp", 0.25, 0.0), Vec3::new(0.75, 0.0, 0.25));
    assert_eq!(at("uvc", 0.75, -0.25), Vec3::new(0.5, 0.75, 0.0));
    assert_eq!(at("sum", 0.75, -0.25), Vec3::new(0.75, 1.25, 1.0));
    assert_eq!(at("diff", 0.0, 0.0), Vec3::splat(0.75));
    // Dots take exactly the two values, the inside one at about the dots' share of the area.
    let mut inside = 0;
    for p in points(10000, -20.0, 20.0) {
        let v = at("dots", p.x, p.y).x;
        assert!(v == 3.0 || v == -1.0, "{v}");
        inside += (v == 3.0) as u32;
    }
    // pi 0.35^2 = 0.385 of a cell, in about half the cells (noise > 0).
    let share = inside as f32 / 10000.0;
    assert!((0.12..0.26).contains(&share), "dots cover {share}");
}

#[test]
fn harlequin_gives_each_primitive_its_colour() {
    let t = textures("Texture \"h\" \"color\" \"harlequin\"");
    let colour = |prim: u32| {
        t.0.eval(
            ConstOrTexture::Texture(TextureId(0)),
            &LookupPoint {
                prim,
                ..LookupPoint::new(Vec3::ZERO, Vec2::ZERO)
            },
        )
    };
    // Radical inverses of 1 (0.5, 1/3, 1/5) and 4 (1/8, 4/9, 4/5).
    assert!(
        (colour(0) - Vec3::new(0.5, 1.0 / 3.0, 0.2))
            .abs()
            .max_element()
            < 1e-6
    );
    assert!(
        (colour(1) - Vec3::new(0.125, 4.0 / 9.0, 0.8))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(colour(31), colour(0));
    let distinct: std::collections::HashSet<[u32; 3]> = (0..31)
        .map(|i| colour(i).to_array().map(f32::to_bits))
        .collect();
    assert_eq!(distinct.len(), 31);
}

#[test]
fn every_brick_bond_shows_bricks_and_mortar_in_proportion() {
    // For the running and stacked bonds a brick cell is brick where each of its three
    // coordinates is past the mortar: (1 - m/w)(1 - m/d)(1 - m/h) of the volume.
    let expected_running = (1.0 - 0.01 / 0.3) * (1.0 - 0.01 / 0.15) * (1.0 - 0.01 / 0.1);
    for (bond, lo, hi) in [
        ("running", expected_running - 0.01, expected_running + 0.01),
        ("stacked", expected_running - 0.01, expected_running + 0.01),
        ("flemish", 0.5, 0.99),
        ("english", 0.5, 0.99),
        ("herringbone", 0.5, 0.99),
        ("basket", 0.5, 0.99),
        ("chain link", 0.5, 0.99),
    ] {
        let t = textures(&format!(
            "Texture \"b\" \"float\" \"brick\" \"string brickbond\" \"{bond}\" \
             \"float bricktex\" 1 \"float mortartex\" 0"
        ));
        let values: Vec<f32> = points(40000, -3.0, 3.0)
            .map(|p| value(&t, "b", p))
            .collect();
        assert!(values.iter().all(|&v| v == 0.0 || v == 1.0), "{bond}");
        let share = values.iter().sum::<f32>() / values.len() as f32;
        assert!((lo..hi).contains(&share), "{bond}: brick share {share}");
    }
}

#[test]
fn brick_modulation_is_one_value_per_brick() {
    // brickmodtex sees the brick's index as its position: an fbm there is constant over a
    // brick, so two points of the same brick get the same product.
    let t = textures(
        "Texture \"mod\" \"float\" \"fbm\"\n\
         Texture \"b\" \"float\" \"brick\" \"string brickbond\" \"stacked\" \"texture brickmodtex\" \"mod\"",
    );
    // Both points are inside brick (1, 2, 1) of the stacked bond (0.3 x 0.15 x 0.1 cells,
    // shifted by the mortar size and 1e-3).
    let a = value(&t, "b", Vec3::new(0.439, 0.364, 0.139));
    let b = value(&t, "b", Vec3::new(0.349, 0.334, 0.169));
    let c = value(&t, "b", Vec3::new(0.139, 0.364, 0.139));
    let expected = noise::fbm(Vec3::new(1.0, 2.0, 1.0), 0.5, 8);
    assert!(expected.abs() > 1e-3);
    assert_eq!(a, b);
    assert!((a - expected).abs() < 1e-6, "{a} vs {expected}");
    // Brick (0, 2, 1) next to it has its own value.
    assert!((c - noise::fbm(Vec3::new(0.0, 2.0, 1.0), 0.5, 8)).abs() < 1e-6);
    assert!((a - c).abs() > 1e-3);
}

#[test]
fn bad_procedural_parameters_are_errors_not_panics() {
    let parse = |s: &str| {
        let mut source = MemorySource::new();
        let text = format!("Camera \"perspective\"\nWorldBegin\n{s}\nWorldEnd\n");
        source.insert("main.lxs", text.as_bytes().into());
        parse_scene("main.lxs", &source).map(|_| ())
    };
    assert!(parse("Texture \"b\" \"float\" \"band\" \"float offsets\" [1 0]").is_err());
    assert!(parse("Texture \"b\" \"float\" \"band\"").is_err());
    assert!(parse("Texture \"b\" \"float\" \"brick\" \"float brickwidth\" 0").is_err());
    // Hostile octave counts are bounded, not an endless loop.
    assert!(parse("Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 2000000000").is_ok());
}

#[test]
fn spectral_textures_are_their_rgb_colours() {
    let t = textures(
        "Texture \"e\" \"color\" \"equalenergy\" \"float energy\" 0.7\n\
         Texture \"flat\" \"color\" \"gaussian\" \"float width\" 1e6 \"float energy\" 0.5\n\
         Texture \"red\" \"color\" \"gaussian\" \"float wavelength\" 620 \"float width\" 20\n\
         Texture \"green\" \"color\" \"gaussian\" \"float wavelength\" 530 \"float width\" 20\n\
         Texture \"blue\" \"color\" \"gaussian\" \"float wavelength\" 450 \"float width\" 20",
    );
    let c = |name: &str| eval_at(&t, name, Vec3::ZERO, Vec2::ZERO);
    assert_eq!(c("e"), Vec3::splat(0.7));
    // A Gaussian far wider than the visible range is flat: its value in every channel.
    assert!(
        (c("flat") - Vec3::splat(0.5)).abs().max_element() < 1e-3,
        "{}",
        c("flat")
    );
    // Narrow bands land in their own channel.
    let (r, g, b) = (c("red"), c("green"), c("blue"));
    assert!(r.x > 2.0 * r.y && r.x > 2.0 * r.z, "red {r}");
    assert!(g.y > g.x && g.y > 2.0 * g.z, "green {g}");
    assert!(b.z > 2.0 * b.x && b.z > 2.0 * b.y, "blue {b}");
}
