//! Monte Carlo checks of every BSDF: energy conservation, agreement of `sample` with `eval`
//! and `pdf`, normalisation of `pdf`, reciprocity, dielectric Fresnel, mix selection.
//! Sample points come from the renderer's own stratified sampler with fixed seeds, so the
//! estimates are deterministic and the tolerances leave room for their measured error.

use std::f32::consts::PI;

use glam::{Affine3A, Vec2, Vec3};

use super::*;
use crate::desc::MaterialDesc;
use crate::geometry::SurfaceHit;
use crate::refs::{ConstOrTexture, Fresnel, MaterialId};
use crate::sampler::PixelSampler;
use crate::texture::Textures;
use glossy::CoatParams;

fn hit_with(ng: Vec3, ns: Vec3) -> SurfaceHit {
    SurfaceHit {
        t: 1.0,
        p: Vec3::ZERO,
        ng,
        ns,
        // Inside a yarn of every cloth weave (the origin is on the edge of one).
        uv: Vec2::new(0.37, 0.61),
        dpdu: Vec3::X,
        dpdv: Vec3::Y,
        shape: 0,
        prim: 0,
    }
}

fn bsdf_of(material: MaterialDesc) -> Bsdf {
    Materials::new(vec![material]).bsdf(
        MaterialId(0),
        &hit_with(Vec3::Z, Vec3::Z),
        &Affine3A::IDENTITY,
        &Textures::default(),
        0.5,
    )
}

fn c(v: f32) -> ConstOrTexture {
    ConstOrTexture::float(v)
}

fn rgb(r: f32, g: f32, b: f32) -> ConstOrTexture {
    ConstOrTexture::color(Vec3::new(r, g, b))
}

fn matte(kd: f32, sigma: f32) -> MaterialDesc {
    MaterialDesc::Matte(Matte {
        kd: c(kd),
        sigma: c(sigma),
    })
}

fn coat(ks: f32, u: f32, v: f32, multibounce: bool) -> CoatParams {
    CoatParams {
        ks: c(ks),
        ka: c(0.0),
        depth: c(0.0),
        uroughness: c(u),
        vroughness: c(v),
        multibounce,
    }
}

fn glossy(kd: f32, ks: f32, u: f32, v: f32, multibounce: bool) -> MaterialDesc {
    MaterialDesc::Glossy(Glossy {
        kd: c(kd),
        coat: coat(ks, u, v, multibounce),
    })
}

fn glossy_lossy(kd: f32, ks: f32, u: f32, v: f32) -> MaterialDesc {
    MaterialDesc::GlossyLossy(glossy_lossy::GlossyLossy {
        kd: c(kd),
        ks: c(ks),
        ka: c(0.0),
        depth: c(0.0),
        uroughness: c(u),
        vroughness: c(v),
    })
}

fn glass(index: f32, roughness: f32, architectural: bool) -> MaterialDesc {
    MaterialDesc::Glass(Glass {
        kr: c(1.0),
        kt: c(1.0),
        index: c(index),
        cauchyb: c(0.0),
        architectural,
        uroughness: c(roughness),
        vroughness: c(roughness),
        index_from_volumes: false,
        dispersion: false,
        volume_dispersion: crate::wavelength::Dispersion::None,
        film: Default::default(),
    })
}

/// A 300 nm film of index 1.5 (magenta at normal incidence).
fn film() -> film::FilmParams {
    film::FilmParams {
        thickness: c(300.0),
        index: c(1.5),
    }
}

fn gold(u: f32, v: f32) -> MaterialDesc {
    MaterialDesc::Metal(Metal {
        fresnel: Fresnel::Conductor {
            eta: Vec3::new(0.143, 0.374, 1.442),
            k: Vec3::new(3.983, 2.385, 1.603),
        },
        uroughness: c(u),
        vroughness: c(v),
    })
}

/// The BSDF of material 0 of `materials` (the others are what it refers to).
fn bsdf_of_set(materials: Vec<MaterialDesc>) -> Bsdf {
    Materials::new(materials).bsdf(
        MaterialId(0),
        &hit_with(Vec3::Z, Vec3::Z),
        &Affine3A::IDENTITY,
        &Textures::default(),
        0.5,
    )
}

fn carpaint_preset(name: &str) -> MaterialDesc {
    let p = carpaint::preset(name).expect("a preset");
    MaterialDesc::CarPaint(CarPaint::from_preset(p, c(0.0), c(0.0)))
}

/// A cloth preset with bright highlights (the cap on its glints binds) on a white surface.
fn cloth_preset(p: &'static cloth::Preset) -> MaterialDesc {
    MaterialDesc::Cloth(Cloth {
        preset: p,
        warp: [rgb(0.3, 0.2, 0.1), c(1.0)],
        weft: [c(0.5), rgb(1.0, 0.5, 0.8)],
        repeat: glam::Vec2::splat(cloth::DEFAULT_REPEAT),
    })
}

fn velvet(kd: f32, p: [f32; 3], thickness: f32) -> MaterialDesc {
    MaterialDesc::Velvet(Velvet {
        kd: c(kd),
        p: p.map(c),
        thickness: c(thickness),
    })
}

fn scatter(kd: f32, g: Vec3) -> MaterialDesc {
    MaterialDesc::Scatter(Scatter {
        kd: c(kd),
        g: ConstOrTexture::color(g),
    })
}

fn shinymetal(kr: f32, ks: f32, r: f32) -> MaterialDesc {
    MaterialDesc::ShinyMetal(ShinyMetal {
        kr: c(kr),
        ks: c(ks),
        uroughness: c(r),
        vroughness: c(r),
        film: Default::default(),
    })
}

fn glossytranslucent(
    kd: f32,
    kt: f32,
    front: CoatParams,
    back: Option<CoatParams>,
) -> MaterialDesc {
    MaterialDesc::GlossyTranslucent(GlossyTranslucent {
        kd: c(kd),
        kt: c(kt),
        front,
        back,
    })
}

/// A glossycoating (material 0) over `base` (material 1).
fn coated(coat: CoatParams, base: MaterialDesc) -> Vec<MaterialDesc> {
    vec![
        MaterialDesc::GlossyCoating(GlossyCoating {
            base: MaterialId(1),
            coat,
        }),
        base,
    ]
}

/// The LuxRender 1.x extras (each a material set whose first material is the one examined).
fn extra_cases() -> Vec<(&'static str, Vec<MaterialDesc>)> {
    let mut cases: Vec<(&'static str, Vec<MaterialDesc>)> = carpaint::PRESETS
        .iter()
        .map(|p| (p.name, vec![carpaint_preset(p.name)]))
        .chain(
            cloth::PRESETS
                .iter()
                .map(|p| (p.name, vec![cloth_preset(p)])),
        )
        .collect();
    cases.extend([
        (
            "carpaint custom ks 1 r 1 (scaled down)",
            vec![MaterialDesc::CarPaint(CarPaint {
                kd: c(1.0),
                ks: [c(1.0), c(1.0), c(1.0)],
                r: [c(1.0), c(0.5), c(0.05)],
                m: [c(0.5), c(0.3), c(0.2)],
                ka: c(0.0),
                depth: c(0.0),
            })],
        ),
        (
            "carpaint absorbing",
            vec![MaterialDesc::CarPaint(CarPaint {
                ka: rgb(0.2, 0.5, 0.9),
                depth: c(0.3),
                ..CarPaint::from_preset(&carpaint::PRESETS[1], c(0.0), c(0.0))
            })],
        ),
        ("velvet default", vec![velvet(0.3, [-2.0, 20.0, 2.0], 0.1)]),
        (
            "velvet white thick",
            vec![velvet(1.0, [-2.0, 20.0, 2.0], 1.0)],
        ),
        ("velvet isotropic", vec![velvet(1.0, [0.0, 0.0, 0.0], 1.0)]),
        (
            "velvet p2 100",
            vec![velvet(1.0, [30.0, 100.0, -50.0], 1.0)],
        ),
        ("scatter isotropic", vec![scatter(1.0, Vec3::ZERO)]),
        (
            "scatter forward",
            vec![scatter(0.8, Vec3::new(0.6, 0.5, 0.7))],
        ),
        ("scatter backward", vec![scatter(1.0, Vec3::splat(-0.5))]),
        ("shinymetal glossy side", vec![shinymetal(0.3, 0.6, 0.2)]),
        ("shinymetal mirror side", vec![shinymetal(0.8, 0.2, 0.2)]),
        (
            "glossytranslucent",
            vec![glossytranslucent(
                0.5,
                1.0,
                coat(0.04, 0.2, 0.2, false),
                None,
            )],
        ),
        (
            "glossytranslucent two coats",
            vec![glossytranslucent(
                0.3,
                0.9,
                coat(0.3, 0.3, 0.3, false),
                Some(coat(0.05, 0.6, 0.6, false)),
            )],
        ),
        (
            "glossytranslucent white",
            vec![glossytranslucent(
                0.0,
                1.0,
                coat(1.0, 0.4, 0.4, false),
                None,
            )],
        ),
        (
            "glossycoating over matte",
            coated(coat(0.5, 0.2, 0.2, false), matte(1.0, 0.0)),
        ),
        (
            "glossycoating over gold r .3",
            coated(coat(0.1, 0.3, 0.3, false), gold(0.3, 0.3)),
        ),
        (
            "glossycoating over mirror",
            coated(
                coat(0.3, 0.4, 0.4, false),
                MaterialDesc::Mirror(Mirror {
                    kr: c(1.0),
                    film: Default::default(),
                }),
            ),
        ),
        (
            "glossycoating smooth over mattetranslucent",
            coated(
                coat(0.2, 0.0, 0.0, false),
                MaterialDesc::MatteTranslucent(MatteTranslucent {
                    kr: c(0.4),
                    kt: c(1.0),
                    sigma: c(0.0),
                    energy_conserving: true,
                }),
            ),
        ),
        (
            "glossycoating over roughglass .4",
            coated(coat(0.3, 0.3, 0.3, false), glass(1.5, 0.4, false)),
        ),
        (
            "glossycoating over velvet",
            coated(coat(1.0, 0.5, 0.5, true), velvet(1.0, [0.0, 2.0, 0.0], 1.0)),
        ),
    ]);
    cases
}

/// Every kind of BSDF over a range of parameters, named for failure messages.
fn cases() -> Vec<(&'static str, Vec<MaterialDesc>)> {
    leaf_cases()
        .into_iter()
        .map(|(name, m)| (name, vec![m]))
        .chain(extra_cases())
        .collect()
}

/// The course's materials over a range of parameters.
fn leaf_cases() -> Vec<(&'static str, MaterialDesc)> {
    vec![
        ("lambert white", matte(1.0, 0.0)),
        ("oren-nayar 20deg", matte(1.0, 20.0)),
        ("oren-nayar 60deg", matte(1.0, 60.0)),
        (
            "mattetranslucent",
            MaterialDesc::MatteTranslucent(MatteTranslucent {
                kr: c(0.5),
                kt: c(1.0),
                sigma: c(0.0),
                energy_conserving: true,
            }),
        ),
        (
            "mattetranslucent rough",
            MaterialDesc::MatteTranslucent(MatteTranslucent {
                kr: c(0.3),
                kt: c(0.9),
                sigma: c(30.0),
                energy_conserving: true,
            }),
        ),
        ("glossy ks .04 r .05", glossy(1.0, 0.04, 0.05, 0.05, false)),
        ("glossy ks .04 r .3", glossy(1.0, 0.04, 0.3, 0.3, false)),
        (
            "glossy seed ks .4 r .075",
            glossy(1.0, 0.4, 0.075, 0.075, false),
        ),
        ("glossy ks 1 r .5", glossy(1.0, 1.0, 0.5, 0.5, false)),
        ("glossy aniso .1/.5", glossy(0.8, 0.2, 0.1, 0.5, false)),
        ("glossy multibounce r 1", glossy(1.0, 0.04, 1.0, 1.0, true)),
        ("glossy multibounce ks 1", glossy(1.0, 1.0, 0.7, 0.7, true)),
        ("glossy smooth coat", glossy(1.0, 0.1, 0.0, 0.0, false)),
        (
            "glossy absorbing",
            MaterialDesc::Glossy(Glossy {
                kd: c(1.0),
                coat: CoatParams {
                    ka: rgb(0.9, 0.3, 0.0),
                    depth: c(0.5),
                    ..coat(0.1, 0.2, 0.2, false)
                },
            }),
        ),
        ("substrate ks .04 r .1", glossy_lossy(1.0, 0.04, 0.1, 0.1)),
        ("substrate ks .5 r .3", glossy_lossy(0.5, 0.5, 0.3, 0.3)),
        ("substrate aniso .05/.4", glossy_lossy(0.8, 0.1, 0.05, 0.4)),
        ("substrate smooth", glossy_lossy(1.0, 0.2, 0.0, 0.0)),
        (
            "substrate absorbing",
            MaterialDesc::GlossyLossy(glossy_lossy::GlossyLossy {
                ka: rgb(0.9, 0.3, 0.0),
                depth: c(0.5),
                ..match glossy_lossy(1.0, 0.1, 0.2, 0.2) {
                    MaterialDesc::GlossyLossy(g) => g,
                    _ => unreachable!(),
                }
            }),
        ),
        (
            "mirror",
            MaterialDesc::Mirror(Mirror {
                kr: c(1.0),
                film: Default::default(),
            }),
        ),
        (
            "mirror film",
            MaterialDesc::Mirror(Mirror {
                kr: c(1.0),
                film: film(),
            }),
        ),
        (
            "glass film",
            match glass(1.5, 0.0, false) {
                MaterialDesc::Glass(g) => MaterialDesc::Glass(Glass { film: film(), ..g }),
                _ => unreachable!(),
            },
        ),
        ("glass 1.5", glass(1.5, 0.0, false)),
        ("glass 2.4", glass(2.4, 0.0, false)),
        ("architectural", glass(1.5, 0.0, true)),
        ("roughglass .001 (default)", glass(1.5, 0.001, false)),
        ("roughglass .1", glass(1.5, 0.1, false)),
        ("roughglass .4", glass(1.5, 0.4, false)),
        ("gold smooth", gold(0.0, 0.0)),
        ("gold r .001", gold(0.001, 0.001)),
        ("gold r .1", gold(0.1, 0.1)),
        ("gold aniso .05/.6", gold(0.05, 0.6)),
        (
            "metal2 index 5",
            MaterialDesc::Metal(Metal {
                fresnel: Fresnel::Index(c(5.0)),
                uroughness: c(0.3),
                vroughness: c(0.3),
            }),
        ),
        (
            "metal2 reflectance",
            MaterialDesc::Metal(Metal {
                fresnel: Fresnel::Reflectance(rgb(1.0, 0.7, 0.3)),
                uroughness: c(0.5),
                vroughness: c(0.5),
            }),
        ),
    ]
}

/// Outgoing directions: a range of elevations (including grazing), from above and below.
fn outgoing() -> Vec<Vec3> {
    let mut dirs = Vec::new();
    for deg in [0.0f32, 30.0, 60.0, 80.0, 88.0] {
        let (s, co) = libm::sincosf(deg.to_radians());
        let phi = 0.7f32;
        let w = Vec3::new(s * libm::cosf(phi), s * libm::sinf(phi), co);
        dirs.push(w);
        dirs.push(Vec3::new(w.x, w.y, -w.z));
    }
    dirs
}

fn sampler(case: usize, dir: usize, index: u32, n: u32, seed: u64) -> PixelSampler {
    PixelSampler::new(case as u32, dir as u32, index, n, seed)
}

fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z)
}

/// What `sample` measures over `n` draws.
struct SampledEstimate {
    /// Mean of f |cos| / pdf over all samples (the directional albedo).
    albedo: Vec3,
    /// The same restricted to non-specular samples.
    non_specular_albedo: Vec3,
    /// Fraction of draws that gave a non-specular direction.
    non_specular_fraction: f64,
}

fn sampled(bsdf: &Bsdf, wo: Vec3, case: usize, dir: usize, n: u32) -> SampledEstimate {
    let mut albedo = Vec3::ZERO.as_dvec3();
    let mut non_specular = Vec3::ZERO.as_dvec3();
    let mut count = 0u32;
    for i in 0..n {
        let mut s = sampler(case, dir, i, n, 11);
        if let Some(bs) = bsdf.sample(wo, s.get_1d(), s.get_2d()) {
            let weight = (bs.f * bs.wi.z.abs() / bs.pdf).as_dvec3();
            albedo += weight;
            if !bs.specular {
                non_specular += weight;
                count += 1;
            }
        }
    }
    SampledEstimate {
        albedo: (albedo / f64::from(n)).as_vec3(),
        non_specular_albedo: (non_specular / f64::from(n)).as_vec3(),
        non_specular_fraction: f64::from(count) / f64::from(n),
    }
}

/// Integral over the sphere of eval |cos| and of pdf (where eval is not zero), with uniform
/// directions.
fn uniform(bsdf: &Bsdf, wo: Vec3, case: usize, dir: usize, n: u32) -> (Vec3, f64) {
    let mut albedo = Vec3::ZERO.as_dvec3();
    let mut pdf = 0.0f64;
    for i in 0..n {
        let wi = uniform_sphere(sampler(case, dir, i, n, 23).get_2d());
        let f = bsdf.eval(wo, wi);
        albedo += (f * wi.z.abs()).as_dvec3();
        // `sample` gives up on directions where f is zero (velvet's clamped phase function
        // has such regions), so the density is compared where f is not.
        if f != Vec3::ZERO {
            pdf += f64::from(bsdf.pdf(wo, wi));
        }
    }
    let scale = 4.0 * std::f64::consts::PI / f64::from(n);
    ((albedo * scale).as_vec3(), pdf * scale)
}

/// Lobes so narrow that uniform directions rarely hit them cannot be checked by uniform
/// integration with a sample count that runs quickly.
fn too_narrow_for_uniform(name: &str) -> bool {
    [
        "r .001",
        "glass .001",
        "r .05",
        "r .075",
        "aniso .05/.6",
        "gold r .1",
        "roughglass .1",
        "aniso .1/.5",
        "aniso .05/.4",
        "substrate smooth",
    ]
    .iter()
    .any(|n| name.contains(n))
}

#[test]
fn directional_albedo_never_exceeds_one() {
    for (ci, (name, material)) in cases().into_iter().enumerate() {
        let bsdf = bsdf_of_set(material);
        let mut albedos = Vec::new();
        for (di, wo) in outgoing().into_iter().enumerate() {
            let a = sampled(&bsdf, wo, ci, di, 1 << 15).albedo.max_element();
            assert!(a.is_finite() && a <= 1.01, "{name} at wo {wo}: albedo {a}");
            albedos.push(format!("{a:.3}"));
        }
        println!(
            "albedo {name:>26} (cos 1 .87 .5 .17 .03, above|below): {}",
            albedos.join(" ")
        );
    }
}

#[test]
fn white_lambert_albedo_is_one_and_lossless_bsdfs_keep_all_energy() {
    for (name, material, expected) in [
        ("lambert", matte(1.0, 0.0), 1.0),
        (
            "mirror",
            MaterialDesc::Mirror(Mirror {
                kr: c(1.0),
                film: Default::default(),
            }),
            1.0,
        ),
        ("glass", glass(1.5, 0.0, false), 1.0),
        ("architectural", glass(1.5, 0.0, true), 1.0),
        ("lambert 0.5", matte(0.5, 0.0), 0.5),
        // A smooth coat over a white diffuse base loses nothing: what the coat does not
        // reflect, the base does.
        (
            "glossy smooth coat white",
            glossy(1.0, 0.2, 0.0, 0.0, false),
            1.0,
        ),
        (
            "glossytranslucent white smooth",
            glossytranslucent(0.0, 1.0, coat(0.1, 0.0, 0.0, false), None),
            1.0,
        ),
        (
            "glossytranslucent white smooth, reflecting half",
            glossytranslucent(0.5, 1.0, coat(0.3, 0.0, 0.0, false), None),
            1.0,
        ),
        // A scattering event keeps its albedo from every direction.
        ("scatter white isotropic", scatter(1.0, Vec3::ZERO), 1.0),
        ("scatter white forward", scatter(1.0, Vec3::splat(0.7)), 1.0),
        ("scatter 0.6 backward", scatter(0.6, Vec3::splat(-0.4)), 0.6),
    ] {
        let bsdf = bsdf_of(material);
        for (di, wo) in outgoing().into_iter().enumerate() {
            let a = sampled(&bsdf, wo, 0, di, 1 << 14).albedo;
            assert!(
                (a - Vec3::splat(expected)).abs().max_element() < 0.01 * expected,
                "{name} at {wo}: {a}"
            );
        }
    }
}

/// LuxRender 1.x's `energyconserving` on mattetranslucent: off, Kt is transmitted as given
/// (Kr 0.5 + Kt 0.8 returns 1.3 of the light, as LuxRender does); on, Kt is scaled by 1 - Kr
/// (0.5 reflected + 0.4 transmitted).
#[test]
fn mattetranslucent_energyconserving_scales_transmission_by_one_minus_kr() {
    for (conserving, reflected, transmitted) in [(false, 0.5, 0.8), (true, 0.5, 0.4)] {
        let bsdf = bsdf_of(MaterialDesc::MatteTranslucent(MatteTranslucent {
            kr: c(0.5),
            kt: c(0.8),
            sigma: c(0.0),
            energy_conserving: conserving,
        }));
        for wo in outgoing() {
            let (r, t) = reflected_energy(&bsdf, wo);
            assert!(
                (r - reflected).abs() < 0.005 && (t - transmitted).abs() < 0.005,
                "energyconserving {conserving}, wo {wo}: reflected {r:.4}, transmitted {t:.4}"
            );
        }
    }
}

#[test]
fn sampling_agrees_with_eval_and_pdf() {
    let mut worst = (0.0f32, "");
    for (ci, (name, material)) in cases().into_iter().enumerate() {
        if too_narrow_for_uniform(name) {
            continue;
        }
        let bsdf = bsdf_of_set(material);
        if bsdf.is_specular() {
            continue;
        }
        for (di, wo) in outgoing().into_iter().enumerate().take(8) {
            let by_sampling = sampled(&bsdf, wo, ci, di, 1 << 15).non_specular_albedo;
            let (by_uniform, _) = uniform(&bsdf, wo, ci, di, 1 << 18);
            let err = (by_sampling - by_uniform).abs().max_element();
            if err > worst.0 {
                worst = (err, name);
            }
            assert!(
                err < 0.01 + 0.03 * by_uniform.max_element(),
                "{name} at wo {wo}: sampled {by_sampling} vs uniform {by_uniform}"
            );
        }
    }
    println!(
        "largest sampled-vs-uniform albedo difference {:.4} ({})",
        worst.0, worst.1
    );
}

#[test]
fn pdf_integrates_to_the_non_specular_fraction() {
    let mut worst = (0.0f64, "");
    for (ci, (name, material)) in cases().into_iter().enumerate() {
        if too_narrow_for_uniform(name) {
            continue;
        }
        let bsdf = bsdf_of_set(material);
        for (di, wo) in outgoing().into_iter().enumerate().take(8) {
            let fraction = sampled(&bsdf, wo, ci, di, 1 << 14).non_specular_fraction;
            let (_, integral) = uniform(&bsdf, wo, ci, di, 1 << 18);
            if (integral - fraction).abs() > worst.0 {
                worst = ((integral - fraction).abs(), name);
            }
            assert!(
                integral <= 1.01 && (integral - fraction).abs() < 0.02,
                "{name} at wo {wo}: pdf integral {integral}, non-specular fraction {fraction}"
            );
        }
    }
    println!(
        "largest |pdf integral - non-specular fraction| {:.4} ({})",
        worst.0, worst.1
    );
}

#[test]
fn reciprocity() {
    let reciprocal = [
        ("lambert", matte(0.7, 0.0)),
        ("oren-nayar", matte(0.7, 40.0)),
        ("gold", gold(0.3, 0.3)),
        ("gold aniso", gold(0.1, 0.6)),
        ("glossy", glossy(0.8, 0.3, 0.2, 0.4, false)),
        ("glossy multibounce", glossy(0.8, 0.3, 0.6, 0.6, true)),
        ("substrate", glossy_lossy(0.8, 0.3, 0.2, 0.4)),
        (
            "mattetranslucent",
            MaterialDesc::MatteTranslucent(MatteTranslucent {
                kr: c(0.4),
                kt: c(0.5),
                sigma: c(25.0),
                energy_conserving: true,
            }),
        ),
    ];
    for (name, material) in reciprocal {
        assert_reciprocal(name, &bsdf_of(material), 1000);
    }
}

/// Checks f(a, b) = f(b, a) on 4096 pairs of directions over the sphere, and that more than
/// `min_nonzero` of the pairs are not black (so the check tested something).
fn assert_reciprocal(name: &str, bsdf: &Bsdf, min_nonzero: usize) {
    let mut checked = 0;
    for i in 0..4096 {
        let mut s = sampler(0, 0, i, 4096, 5);
        let a = uniform_sphere(s.get_2d());
        let b = uniform_sphere(s.get_2d());
        let (fab, fba) = (bsdf.eval(a, b), bsdf.eval(b, a));
        let scale = fab.max_element().max(fba.max_element());
        if scale > 0.0 {
            checked += 1;
            assert!(
                (fab - fba).abs().max_element() <= 1e-4 * scale,
                "{name}: f({a}, {b}) = {fab}, f({b}, {a}) = {fba}"
            );
        }
    }
    assert!(
        checked > min_nonzero,
        "{name}: only {checked} non-zero pairs"
    );
}

#[test]
fn extras_are_reciprocal() {
    // scatter is left out: like a volume's scattering event it divides by cos_i alone.
    let reciprocal = [
        (
            "carpaint polaris silber",
            vec![carpaint_preset("polaris silber")],
        ),
        ("velvet", vec![velvet(0.8, [-2.0, 20.0, 2.0], 0.3)]),
        ("cloth denim", vec![cloth_preset(&cloth::PRESETS[0])]),
        (
            "glossytranslucent two coats",
            vec![glossytranslucent(
                0.3,
                0.9,
                coat(0.3, 0.3, 0.3, false),
                Some(coat(0.05, 0.6, 0.6, false)),
            )],
        ),
        (
            "glossycoating over gold",
            coated(coat(0.1, 0.3, 0.3, false), gold(0.3, 0.3)),
        ),
        (
            "glossycoating absorbing over matte",
            coated(
                CoatParams {
                    ka: rgb(0.5, 0.2, 0.1),
                    depth: c(0.4),
                    ..coat(0.2, 0.4, 0.2, true)
                },
                matte(0.7, 0.0),
            ),
        ),
    ];
    for (name, materials) in reciprocal {
        // Velvet is zero where its clamped phase function is, a good part of the sphere.
        assert_reciprocal(name, &bsdf_of_set(materials), 500);
    }
}

/// Fraction of the energy `sample` reflects to the side of `wo`, with stratified lobe choice.
fn reflected_energy(bsdf: &Bsdf, wo: Vec3) -> (f64, f64) {
    let n = 1 << 14;
    let (mut reflected, mut transmitted) = (0.0, 0.0);
    for i in 0..n {
        let u_lobe = (i as f32 + 0.5) / n as f32;
        if let Some(bs) = bsdf.sample(wo, u_lobe, Vec2::splat(0.5)) {
            let weight = f64::from(bs.f.x * bs.wi.z.abs() / bs.pdf);
            if bs.wi.z * wo.z > 0.0 {
                reflected += weight;
            } else {
                transmitted += weight;
            }
        }
    }
    (reflected / f64::from(n), transmitted / f64::from(n))
}

#[test]
fn glass_reflects_four_percent_at_normal_incidence_and_totally_beyond_critical_angle() {
    let bsdf = bsdf_of(glass(1.5, 0.0, false));
    let (r, t) = reflected_energy(&bsdf, Vec3::Z);
    assert!(
        (r - 0.04).abs() < 1e-3 && (t - 0.96).abs() < 1e-3,
        "R {r} T {t}"
    );
    // From inside the same interface, also 4 percent.
    let (r, _) = reflected_energy(&bsdf, -Vec3::Z);
    assert!((r - 0.04).abs() < 1e-3, "R inside {r}");

    let critical = libm::asinf(1.0f32 / 1.5);
    let inside = |angle: f32| Vec3::new(libm::sinf(angle), 0.0, -libm::cosf(angle));
    let (r, t) = reflected_energy(&bsdf, inside(critical + 0.02));
    assert!(
        (r - 1.0).abs() < 1e-6 && t == 0.0,
        "beyond critical: R {r} T {t}"
    );
    let (_, t) = reflected_energy(&bsdf, inside(critical - 0.1));
    assert!(t > 0.5, "below critical: T {t}");

    // Refraction obeys Snell's law.
    let wo = Vec3::new(libm::sinf(0.5f32), 0.0, libm::cosf(0.5f32));
    let bs = bsdf.sample(wo, 0.99, Vec2::ZERO).unwrap();
    let sin_t = (1.0 - bs.wi.z * bs.wi.z).sqrt();
    assert!(
        (sin_t * 1.5 - libm::sinf(0.5f32)).abs() < 1e-5 && bs.wi.x < 0.0,
        "{}",
        bs.wi
    );
}

#[test]
fn architectural_glass_does_not_bend_light() {
    let bsdf = bsdf_of(glass(1.5, 0.0, true));
    let wo = Vec3::new(0.3, -0.4, 0.5).normalize();
    let bs = bsdf.sample(wo, 0.999, Vec2::ZERO).unwrap();
    assert!((bs.wi + wo).length() < 1e-6, "{}", bs.wi);
    // The pane reflects more than one interface (two faces): 2R/(1+R) at normal incidence.
    let (r, _) = reflected_energy(&bsdf, Vec3::Z);
    assert!((r - 0.08 / 1.04).abs() < 1e-3, "{r}");
}

#[test]
fn rough_glass_transmits_most_at_normal_incidence() {
    let bsdf = bsdf_of(glass(1.5, 0.2, false));
    let mut transmitted = 0.0f64;
    let n = 1 << 15;
    for i in 0..n {
        let mut s = sampler(0, 0, i, n, 3);
        if let Some(bs) = bsdf.sample(Vec3::Z, s.get_1d(), s.get_2d()) {
            if bs.wi.z < 0.0 {
                transmitted += f64::from(bs.f.x * bs.wi.z.abs() / bs.pdf);
            }
        }
    }
    let t = transmitted / f64::from(n);
    assert!(t > 0.93 && t < 0.97, "{t}");
}

#[test]
fn oren_nayar_with_zero_sigma_is_lambert_and_rough_matte_backscatters() {
    let lambert = bsdf_of(matte(0.6, 0.0));
    let wo = Vec3::new(0.8, 0.0, 0.6);
    let back = Vec3::new(0.6, 0.0, 0.8);
    let forward = Vec3::new(-0.6, 0.0, 0.8);
    assert!((lambert.eval(wo, back).x - 0.6 / PI).abs() < 1e-6);
    let rough = bsdf_of(matte(0.6, 40.0));
    assert!(rough.eval(wo, back).x > rough.eval(wo, forward).x);
}

#[test]
fn shading_normals_do_not_leak_light() {
    // The shading normal leans 30 degrees away from the geometric one.
    let ns = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
    let hit = hit_with(Vec3::Z, ns);
    let bsdf = Materials::new(vec![matte(1.0, 0.0)]).bsdf(
        MaterialId(0),
        &hit,
        &Affine3A::IDENTITY,
        &Textures::default(),
        0.0,
    );
    let wo = Vec3::new(0.0, 0.6, 0.8);
    // Above the shading plane but below the geometric surface: no reflection.
    let below_surface = Vec3::new(0.8, 0.0, -0.2).normalize();
    assert!(below_surface.dot(ns) > 0.0);
    assert_eq!(bsdf.eval(wo, below_surface), Vec3::ZERO);
    assert!(bsdf.eval(wo, Vec3::Z).x > 0.0);
    // No sample comes back from below the geometric surface.
    for i in 0..4096 {
        let mut s = sampler(0, 0, i, 4096, 9);
        if let Some(bs) = bsdf.sample(wo, s.get_1d(), s.get_2d()) {
            assert!(bs.wi.z > 0.0, "{}", bs.wi);
        }
    }
}

#[test]
fn mix_chooses_each_side_in_proportion_to_amount() {
    let materials = Materials::new(vec![
        matte(0.2, 0.0),
        matte(0.8, 0.0),
        MaterialDesc::Mix(Mix {
            a: MaterialId(0),
            b: MaterialId(1),
            amount: c(0.3),
        }),
        matte(0.5, 0.0),
        MaterialDesc::Mix(Mix {
            a: MaterialId(2),
            b: MaterialId(3),
            amount: c(0.5),
        }),
    ]);
    let hit = hit_with(Vec3::Z, Vec3::Z);
    let textures = Textures::default();
    let count = |id: u32| {
        let n = 10_000;
        let mut chosen = [0u32; 3];
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let kd = materials
                .bsdf(MaterialId(id), &hit, &Affine3A::IDENTITY, &textures, u)
                .eval(Vec3::Z, Vec3::Z)
                .x
                * PI;
            let index = [0.2f32, 0.8, 0.5]
                .iter()
                .position(|k| (k - kd).abs() < 1e-5)
                .expect("a leaf's albedo");
            chosen[index] += 1;
        }
        chosen.map(|c| f64::from(c) / f64::from(n))
    };
    let single = count(2);
    assert!(
        (single[1] - 0.3).abs() < 0.002 && (single[0] - 0.7).abs() < 0.002,
        "{single:?}"
    );
    let nested = count(4);
    let expected = [0.35, 0.15, 0.5];
    for (got, want) in nested.iter().zip(expected) {
        assert!((got - want).abs() < 0.002, "{nested:?}");
    }
}

#[test]
fn null_passes_through_and_bad_ids_fall_back_to_matte() {
    assert!(bsdf_of(MaterialDesc::Null(Null)).is_pass_through());
    let materials = Materials::new(vec![MaterialDesc::Mix(Mix {
        a: MaterialId(0),
        b: MaterialId(0),
        amount: c(0.5),
    })]);
    let hit = hit_with(Vec3::Z, Vec3::Z);
    for id in [0, 7] {
        let bsdf = materials.bsdf(
            MaterialId(id),
            &hit,
            &Affine3A::IDENTITY,
            &Textures::default(),
            0.3,
        );
        assert!((bsdf.eval(Vec3::Z, Vec3::Z).x * PI - 0.9).abs() < 1e-5);
    }
}
