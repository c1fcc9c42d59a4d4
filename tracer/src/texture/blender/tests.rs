//! The blender_* textures: the noise-free ones (blend, magic, wood's bands and rings, cell
//! noise) against LuxRender 1.x's own formulas compiled unchanged, the noise-based ones by
//! range, mean and determinism, and brightness and contrast.

use glam::{Vec2, Vec3};

use super::noise_basis::{voronoi, Metric, NoiseBasis};
use crate::assets::MemorySource;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::parse_scene;
use crate::texture::{LookupPoint, Textures};

/// The textures of `statements` (warnings allowed: the noise-table note) and a lookup of the
/// last one at a point.
fn texture(statements: &str) -> impl Fn(Vec3) -> f32 {
    let mut source = MemorySource::new();
    let text = format!("Camera \"perspective\"\nWorldBegin\n{statements}\nWorldEnd\n");
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        desc.warnings
            .iter()
            .all(|w| w.message.contains("random tables")),
        "{:?}",
        desc.warnings
    );
    let last = TextureId(desc.textures.len() as u32 - 1);
    let textures = Textures::new(&desc.textures, &source).unwrap();
    move |p| {
        textures
            .eval(ConstOrTexture::Texture(last), &LookupPoint::new(p, Vec2::ZERO))
            .x
    }
}

const POINTS: [Vec3; 4] = [
    Vec3::new(0.3, 0.7, -1.2),
    Vec3::new(0.25, -0.5, 0.125),
    Vec3::new(-0.79, 0.3, 0.22),
    Vec3::new(0.05, 0.05, 0.5),
];

fn near(a: f32, b: f32) -> bool {
    (a - b).abs() < 2e-6
}

#[test]
fn blend_matches_luxrender() {
    // Types lin .. halo, then radial with x and y swapped, at the four points.
    let reference: [[f32; 7]; 4] = [
        [0.65, 0.422_499_96, 0.718_249_9, 0.75, 0.0, 0.0, 0.564_440_5],
        [
            0.625,
            0.390_625,
            0.683_593_75,
            0.4375,
            0.427_178_03,
            0.182_481_07,
            0.926_208_2,
        ],
        [
            0.105,
            0.011_025,
            0.030_759_744,
            0.3775,
            0.126_787_54,
            0.016_075_08,
            0.307_761_43,
        ],
        [
            0.525,
            0.275_624_96,
            0.537_468_7,
            0.525,
            0.495_024_77,
            0.245_049_52,
            0.625,
        ],
    ];
    for (kind, name) in super::blend::TYPES.iter().enumerate() {
        let flip = if *name == "radial" { "true" } else { "false" };
        let t = texture(&format!(
            "Texture \"b\" \"float\" \"blender_blend\" \"string type\" \"{name}\" \"bool flipxy\" \"{flip}\""
        ));
        for (p, r) in POINTS.iter().zip(reference) {
            assert!(
                near(t(*p), r[kind]),
                "{name} at {p}: {} vs {}",
                t(*p),
                r[kind]
            );
        }
    }
}

#[test]
fn magic_matches_luxrender_at_every_depth_with_brightness_and_contrast() {
    let reference: [[f32; 12]; 4] = [
        [
            0.844_350_16,
            0.955_785_63,
            0.698_347_03,
            0.731_456_04,
            0.860_665_8,
            0.576_024_9,
            0.868_952_6,
            0.797_078_4,
            0.787_436_9,
            0.990_803_2,
            0.796_934_6,
            0.796_934_6,
        ],
        [
            0.817_535_34,
            0.937_764_94,
            0.716_765_4,
            0.752_066_7,
            0.884_597_84,
            0.526_820_36,
            0.856_575_5,
            0.799_531_16,
            0.777_511,
            0.987_118_5,
            0.812_068_34,
            0.812_068_34,
        ],
        [
            0.826_992_6,
            0.935_324_5,
            0.715_828_2,
            0.784_287_75,
            0.987_136_2,
            0.667_431_06,
            0.938_435_7,
            0.888_031_54,
            0.871_224_8,
            0.969_400_9,
            0.760_925_4,
            0.760_925_4,
        ],
        [
            0.791_157_37,
            0.684_894_26,
            0.564_939_74,
            0.728_352_25,
            0.947_321_3,
            0.876_846_7,
            1.0,
            1.0,
            1.0,
            1.0,
            0.774_157_9,
            0.774_157_9,
        ],
    ];
    for depth in 0..12 {
        let turbulence = if depth == 3 { 2.5 } else { 5.0 };
        let t = texture(&format!(
            "Texture \"m\" \"float\" \"blender_magic\" \"integer noisedepth\" {depth} \
             \"float turbulence\" {turbulence} \"float bright\" 1.2 \"float contrast\" 0.8"
        ));
        for (p, r) in POINTS.iter().zip(reference) {
            let got = t(*p);
            assert!(
                (got - r[depth]).abs() < 1e-5,
                "depth {depth} at {p}: {got} vs {}",
                r[depth]
            );
        }
    }
}

#[test]
fn cell_noise_is_blenders_hash() {
    let reference = [0.146_130_15, 0.618_527, 0.760_381_1, 0.633_362_95];
    for (p, r) in POINTS.iter().zip(reference) {
        assert_eq!(NoiseBasis::CellNoise.unsigned(*p * 13.0), r, "at {p}");
    }
}

#[test]
fn wood_bands_and_rings_follow_their_wave_exactly() {
    use std::f32::consts::TAU;
    let sin = texture("Texture \"w\" \"float\" \"blender_wood\"");
    let saw = texture("Texture \"w\" \"float\" \"blender_wood\" \"string noisebasis2\" \"saw\"");
    let tri = texture(
        "Texture \"w\" \"float\" \"blender_wood\" \"string type\" \"rings\" \"string noisebasis2\" \"tri\"",
    );
    for p in POINTS {
        let a = (p.x + p.y + p.z) * 10.0;
        assert!(near(sin(p), 0.5 + 0.5 * libm::sinf(a)), "sin at {p}");
        assert!(
            near(saw(p), a.rem_euclid(TAU) / TAU),
            "saw at {p}: {}",
            saw(p)
        );
        // A triangle wave: 1 at multiples of 2 pi, 0 half way.
        let r = p.length() * 20.0 / TAU;
        assert!(
            near(tri(p), 1.0 - 2.0 * (r - r.round()).abs()),
            "tri at {p}"
        );
    }
}

/// Mean, minimum and maximum of a texture over a spread of points in [-2, 2]^3.
fn stats(t: &dyn Fn(Vec3) -> f32) -> (f32, f32, f32) {
    let values: Vec<f32> = (0..20000)
        .map(|i| {
            let f = |k: f32| (i as f32 * k).fract();
            t(Vec3::new(f(0.618_034), f(0.754_877_7), f(0.569_840_3)) * 4.0 - 2.0)
        })
        .collect();
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    let lo = values.iter().copied().fold(f32::MAX, f32::min);
    let hi = values.iter().copied().fold(f32::MIN, f32::max);
    (mean, lo, hi)
}

#[test]
fn noise_textures_stay_in_range_and_vary() {
    // Means as Blender's formulas give them: a basis centred on 0.5 stays there; hard noise,
    // crackle, the sharper marble and the terrains move it; signed sums (musgrave's fbm,
    // distorted noise) are clamped at 0 by the brightness and contrast step; white noise of
    // depth 2 averages 1.5^3 / 27 = 0.125.
    for (ty, params, mean_range) in [
        ("blender_clouds", "", 0.45..0.55),
        ("blender_clouds", "\"string type\" \"color\"", 0.45..0.55),
        (
            "blender_clouds",
            "\"string noisetype\" \"hard_noise\"",
            0.15..0.3,
        ),
        (
            "blender_clouds",
            "\"string noisebasis\" \"voronoi_crackle\"",
            0.7..0.9,
        ),
        (
            "blender_clouds",
            "\"string noisebasis\" \"cell_noise\"",
            0.45..0.55,
        ),
        ("blender_wood", "\"string type\" \"ringnoise\"", 0.45..0.55),
        ("blender_marble", "", 0.45..0.55),
        (
            "blender_marble",
            "\"string type\" \"sharper\" \"string noisebasis2\" \"tri\"",
            0.7..0.9,
        ),
        ("blender_musgrave", "\"float outscale\" 0.5", 0.45..0.55),
        (
            "blender_musgrave",
            "\"string type\" \"ridged_multifractal\" \"float octs\" 3.5",
            0.7..0.9,
        ),
        (
            "blender_musgrave",
            "\"string type\" \"hybrid_multifractal\"",
            0.9..1.0,
        ),
        (
            "blender_musgrave",
            "\"string type\" \"hetero_terrain\"",
            0.9..1.0,
        ),
        (
            "blender_musgrave",
            "\"string type\" \"fbm\" \"string noisebasis\" \"improved_perlin\"",
            0.08..0.18,
        ),
        ("blender_stucci", "", 0.45..0.55),
        ("blender_stucci", "\"string type\" \"wall_out\"", 0.45..0.55),
        ("blender_voronoi", "", 0.45..0.6),
        (
            "blender_voronoi",
            "\"string distmetric\" \"manhattan\" \"float w1\" 1 \"float w2\" 1",
            0.8..0.95,
        ),
        ("blender_voronoi", "\"integer coltype\" 2", 0.3..0.5),
        (
            "blender_distortednoise",
            "\"float distamount\" 3",
            0.05..0.2,
        ),
        ("blender_noise", "", 0.11..0.14),
    ] {
        let statement = format!("Texture \"t\" \"float\" \"{ty}\" {params}");
        let t = texture(&statement);
        let (mean, lo, hi) = stats(&t);
        assert!(lo >= 0.0 && hi <= 1.0, "{statement}: [{lo}, {hi}]");
        assert!(hi - lo > 0.2, "{statement} varies: [{lo}, {hi}]");
        assert!(mean_range.contains(&mean), "{statement}: mean {mean}");
    }
}

#[test]
fn textures_blend_between_tex1_and_tex2() {
    // lin at x = 0.5 is 0.75: a quarter of the way from tex2 back to tex1.
    let t = texture("Texture \"b\" \"float\" \"blender_blend\" \"float tex1\" 2 \"float tex2\" 6");
    assert!(near(t(Vec3::new(0.5, 0.0, 0.0)), 5.0));
    // Contrast 2 and brightness 1.3: (0.75 - 0.5) 2 + 1.3 - 0.5 = 1.3, clamped to 1.
    let t = texture(
        "Texture \"b\" \"float\" \"blender_blend\" \"float contrast\" 2 \"float bright\" 1.3",
    );
    assert_eq!(t(Vec3::new(0.5, 0.0, 0.0)), 1.0);
    assert!(near(t(Vec3::new(-0.5, 0.0, 0.0)), 0.3));
}

#[test]
fn voronoi_distances_are_sorted_and_the_nearest_is_a_feature_point() {
    for i in 0..500 {
        let f = |k: f32| (i as f32 * k).fract();
        let p = Vec3::new(f(0.618_034), f(0.754_877_7), f(0.569_840_3)) * 20.0 - 10.0;
        let (da, pa) = voronoi(p, Metric::Actual);
        assert!(da[0] <= da[1] && da[1] <= da[2] && da[2] <= da[3], "{da:?}");
        assert!(near(da[0], (p - pa[0]).length()));
        // One feature point per unit cell: the nearest is never farther than the cell's
        // diagonal.
        assert!(da[0] < 3f32.sqrt());
        assert_eq!(voronoi(pa[0], Metric::Actual).0[0], 0.0);
    }
}
