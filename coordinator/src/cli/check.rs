//! `yat check`: parse a scene and print a summary, then every statement or parameter that is
//! not rendered as LuxRender would (each occurrence, with file:line:col), the documented
//! differences YAT accepts, the parameters LuxRender reads that change nothing in its image
//! (each with why), the notes about the file that leave the image as LuxRender's, and the
//! count of the first kind only.
//!
//! Exit status: 0 when the scene parses (whatever the count), 1 when it does not; with
//! `--strict`, also 1 when the count is not 0.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use yat_tracer::budget::Limit;
use yat_tracer::camera::aperture::{Aperture, LensDistribution};
use yat_tracer::camera::MAX_FOCAL_DISTANCE;
use yat_tracer::desc::{
    AssetKind, CameraKind, FilterKind, Geometry, LightDesc, SceneDesc, ToneMap,
};
use yat_tracer::diag::{Severity, Warning};
use yat_tracer::film::LightGroups;
use yat_tracer::integrator::Transport;
use yat_tracer::render::convergence::ConvergenceHalt;
use yat_tracer::render::sampling::Sampling;
use yat_tracer::render::{RenderOverrides, RenderSettings};

use super::budget::BudgetArgs;
use crate::scene::{ParsedScene, Warnings};

#[derive(clap::Args)]
pub struct CheckArgs {
    /// The main .lxs file.
    pub scene: PathBuf,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// Exit with status 1 when any statement or parameter is not rendered as LuxRender would
    /// (without it, the status is 0 whenever the scene parses).
    #[arg(long)]
    pub strict: bool,
}

/// Occurrences of one warning listed with their positions; the rest are counted.
const LISTED_PER_WARNING: usize = 10;

pub fn run(args: CheckArgs) -> anyhow::Result<()> {
    let scene = ParsedScene::load_within(&args.scene, Warnings::Keep, args.budget.budget())?;
    print!(
        "{}",
        summary(
            &args.scene.display().to_string(),
            &scene.desc,
            scene.parse_time.as_secs_f64()
        )
    );
    print!("{}", memory(&scene));
    let differences = differences(&scene.desc.warnings);
    print!("{}", listing(&scene.desc.warnings, differences));
    if args.strict && differences > 0 {
        anyhow::bail!(
            "--strict: {differences} statements or parameters not rendered as LuxRender would"
        );
    }
    Ok(())
}

/// How many statements or parameters are not rendered as LuxRender would: every occurrence.
fn differences(warnings: &[Warning]) -> u64 {
    warnings
        .iter()
        .filter(|w| w.severity == Severity::Differs)
        .map(Warning::occurrences)
        .sum()
}

/// The differences, the accepted differences, the parameters without effect and the notes,
/// each occurrence with its position (the first [`LISTED_PER_WARNING`] of a warning; "and N
/// more" for the rest), then the count of the differences.
fn listing(warnings: &[Warning], differences: u64) -> String {
    let mut s = String::new();
    for (severity, title) in [
        (Severity::Differs, "not rendered as LuxRender would"),
        (Severity::Accepted, "documented differences (accepted)"),
        (Severity::NoEffect, "no effect on the image"),
        (Severity::Note, "notes (rendered as LuxRender would)"),
    ] {
        let of_kind: Vec<&Warning> = warnings.iter().filter(|w| w.severity == severity).collect();
        if of_kind.is_empty() {
            continue;
        }
        let n: u64 = of_kind.iter().map(|w| w.occurrences()).sum();
        let _ = writeln!(s, "{title}: {n}");
        for w in of_kind {
            let _ = writeln!(s, "  {}: {}", w.pos, w.message);
            let listed = w.also_at.iter().take(LISTED_PER_WARNING - 1);
            for pos in listed.clone() {
                let _ = writeln!(s, "  {pos}: the same");
            }
            let more = w.occurrences() - 1 - listed.len() as u64;
            if more > 0 {
                let _ = writeln!(s, "  ... and {more} more");
            }
        }
    }
    let _ = writeln!(
        s,
        "{differences} statements or parameters not rendered as LuxRender would"
    );
    s
}

/// The build's memory estimate against the budget, and the film an in-process render of the
/// file's resolution adds.
fn memory(scene: &ParsedScene) -> String {
    let mib = |bytes: u64| Limit::MemoryBytes.amount(bytes);
    let build = scene.desc.spent.spent(Limit::MemoryBytes);
    let overrides = RenderOverrides::default();
    let settings = RenderSettings::resolve(&scene.desc, &overrides);
    let sampling = ConvergenceHalt::resolve(&scene.desc, &overrides)
        .map_or(Sampling::Uniform, Sampling::Converging);
    let film = scene.film_bytes(&settings, &sampling);
    let limit = scene.budget.max(Limit::MemoryBytes);
    let limit = if limit == u64::MAX {
        "no limit".to_string()
    } else {
        format!("limit {} ({})", mib(limit), Limit::MemoryBytes.flag())
    };
    format!(
        "memory       {} estimated to build, {} more for the {}x{} film in-process; {limit}\n",
        mib(build),
        mib(film),
        settings.width,
        settings.height
    )
}

/// The halts a render of the scene takes, the first met ending it, and where each comes from.
/// The scene's light groups, each with its settings where they are not LuxRender's defaults,
/// and what the render keeps of them; None without `LightGroup`s.
fn light_groups(groups: &LightGroups) -> Option<String> {
    if groups.groups.is_empty() || (groups.groups.len() == 1 && groups.groups[0].is_plain()) {
        return None;
    }
    let named: Vec<String> = groups
        .groups
        .iter()
        .map(|g| {
            let mut settings = Vec::new();
            if !g.enabled {
                settings.push("disabled".to_string());
            }
            if g.scale != 1.0 {
                settings.push(format!("scale {}", g.scale));
            }
            if g.rgb_scale != glam::Vec3::ONE {
                let c = g.rgb_scale;
                settings.push(format!("rgbscale {} {} {}", c.x, c.y, c.z));
            }
            if g.temperature > 0.0 {
                settings.push(format!("{} K", g.temperature));
            }
            if settings.is_empty() {
                g.name.clone()
            } else {
                format!("{} ({})", g.name, settings.join(", "))
            }
        })
        .collect();
    let kept = if groups.layered() {
        "; the image is their weighed sum, each a layer of the EXR (lightgroup.<name>.R/G/B)"
    } else {
        "; the image is its light weighed"
    };
    Some(format!(
        "{}: {}{kept}",
        groups.groups.len(),
        named.join(", ")
    ))
}

fn halts(desc: &SceneDesc) -> String {
    let overrides = RenderOverrides::default();
    let settings = RenderSettings::resolve(desc, &overrides);
    let converging = ConvergenceHalt::resolve(desc, &overrides);
    let samples_from = if desc.film.haltspp.is_some() {
        "haltspp"
    } else if converging.is_some() {
        "the most a render halted by convergence takes"
    } else if desc.sampler.pixel_samples.is_some() {
        "the sampler's pixelsamples"
    } else {
        "YAT's default"
    };
    let mut halts = vec![format!("{} samples a pixel ({samples_from})", settings.spp)];
    if let Some(t) = desc.film.halttime {
        halts.push(format!("{t} s (halttime)"));
    }
    if let Some(halt) = converging {
        halts.push(format!(
            "at most {}% of the pixels changing visibly between tests every {} samples \
             (haltthreshold)",
            halt.threshold * 100.0,
            halt.step
        ));
    }
    let which = match halts.len() {
        1 => String::new(),
        _ => "the first met ends the render: ".to_string(),
    };
    format!(
        "{which}{} (--spp, --time-limit and --halt-threshold override them)",
        halts.join(", ")
    )
}

/// Numbers as a person reads them: LuxRender's "infinite" 1e30 stays short.
fn short(v: f32) -> String {
    if v.abs() >= 1e6 {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Why `transport` runs for a scene asking for `requested`, and what choosing the other costs
/// (per-sample figures of bench/RESULTS.md, "Bidirectional against path tracing, every
/// scene"); None where the scene gets what it asks for and loses nothing.
fn transport_reason(
    requested: &str,
    transport: Transport,
    caustics: Option<(&str, &str)>,
) -> Option<String> {
    match (requested, transport, caustics) {
        ("bidirectional", Transport::Bidirectional, Some((light, material))) => Some(format!(
            "bidirectional: the {light} light's caustics off \"{material}\" need light subpaths; \
             a sample costs 2-4x a path-traced one, and --integrator path renders faster \
             without those caustics"
        )),
        ("bidirectional", Transport::Path, None) => Some(
            "path tracing: no caustics of point, spot or distant lights here, so the same image \
             as bidirectional at 2-4x the samples a second; --integrator bidirectional chooses it"
                .to_string(),
        ),
        (_, Transport::Path | Transport::DirectLighting, Some((light, material))) => Some(format!(
            "path tracing misses the {light} light's caustics off \"{material}\": \
                 --integrator bidirectional renders them"
        )),
        _ => None,
    }
}

fn counts<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let mut m = BTreeMap::new();
    for n in names {
        *m.entry(n).or_insert(0usize) += 1;
    }
    if m.is_empty() {
        return "none".into();
    }
    m.iter()
        .map(|(k, v)| format!("{v} {k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn summary(path: &str, d: &SceneDesc, seconds: f64) -> String {
    let mut s = String::new();
    let c = &d.camera;
    let f = &d.film;
    let _ = writeln!(s, "scene        {path}");
    let _ = writeln!(s, "resolution   {}x{}", f.xresolution, f.yresolution);
    let camera = match c.kind {
        CameraKind::Perspective { fov } => format!("perspective fov {fov}"),
        CameraKind::Orthographic => "orthographic".to_string(),
        CameraKind::Fisheye { fov } => format!("fisheye fov {fov}"),
    };
    let sw = c.screen_window;
    let focus = if c.autofocus {
        "autofocus (the first hit through the screen centre)".to_string()
    } else if c.focal_distance >= MAX_FOCAL_DISTANCE {
        format!("{} (infinity)", short(c.focal_distance))
    } else {
        short(c.focal_distance)
    };
    let aperture = match c.aperture {
        a if a.is_round() => String::new(),
        Aperture {
            blades,
            distribution,
        } => {
            let weighting = match distribution {
                LensDistribution::Uniform => "uniform".to_string(),
                LensDistribution::Exponential { power } => format!("exponential, power {power}"),
                LensDistribution::InverseExponential { power } => {
                    format!("inverse exponential, power {power}")
                }
                LensDistribution::Gaussian => "gaussian".to_string(),
                LensDistribution::InverseGaussian => "inverse gaussian".to_string(),
            };
            format!(", aperture {blades} blades ({weighting})")
        }
    };
    let _ = writeln!(
        s,
        "camera       {camera}, lensradius {}{aperture}, focaldistance {focus}, screenwindow [{} {} {} {}]",
        c.lens_radius,
        sw[0],
        sw[1],
        sw[2],
        sw[3]
    );
    let eye = c.camera_to_world.transform_point3(glam::Vec3::ZERO);
    let dir = c
        .camera_to_world
        .transform_vector3(glam::Vec3::Z)
        .normalize();
    let _ = writeln!(
        s,
        "             at ({:.3}, {:.3}, {:.3}) looking along ({:.3}, {:.3}, {:.3})",
        eye.x, eye.y, eye.z, dir.x, dir.y, dir.z
    );
    let tonemap = match f.tonemap {
        ToneMap::AutoLinear => "autolinear".to_string(),
        ToneMap::Linear {
            sensitivity,
            exposure,
            fstop,
            gamma,
        } => {
            format!(
                "linear (sensitivity {sensitivity}, exposure {exposure}, fstop {fstop}, gamma \
                 {gamma})"
            )
        }
        ToneMap::Reinhard {
            prescale,
            postscale,
            burn,
        } => {
            format!("reinhard (prescale {prescale}, postscale {postscale}, burn {burn})")
        }
        ToneMap::Contrast { ywa } => format!("contrast (ywa {ywa})"),
    };
    let _ = writeln!(
        s,
        "film         gamma {}, tonemap {tonemap}, output \"{}\"",
        f.gamma, f.filename
    );
    let _ = writeln!(s, "halts        {}", halts(d));
    let files: Vec<String> = f
        .outputs
        .files(false)
        .iter()
        .map(|file| format!("{}.{} ({})", f.filename, file.extension(), file.describe()))
        .collect();
    let files = if files.is_empty() {
        "none (the Film writes no PNG, TGA or EXR)".to_string()
    } else {
        files.join(", ")
    };
    let limit = if f.outputs.write_png || f.outputs.write_tga {
        format!(
            "; PNG and TGA colours limited by \"{}\"",
            f.outputs.ldr_clamp.name()
        )
    } else {
        String::new()
    };
    let _ = writeln!(s, "files        {files}{limit}");
    let filter = match d.filter.kind {
        FilterKind::Box => "box".to_string(),
        FilterKind::Triangle => "triangle".to_string(),
        FilterKind::Gaussian { alpha } => format!("gaussian (alpha {alpha})"),
        FilterKind::Mitchell { b, c, supersample } => format!(
            "mitchell (B {b:.3}, C {c:.3}, radial{})",
            if supersample { ", supersampled" } else { "" }
        ),
        FilterKind::CatmullRom => "catmullrom".to_string(),
        FilterKind::BlackmanHarris => "blackmanharris".to_string(),
        FilterKind::Sinc { tau } => format!("sinc (tau {tau})"),
    };
    let _ = writeln!(
        s,
        "filter       {filter}, width {} x {}",
        d.filter.xwidth, d.filter.ywidth
    );
    let i = &d.integrator;
    let transport = d.transport();
    let runs = match transport {
        Transport::DirectLighting => format!(
            "directlighting, {} specular bounces",
            i.max_depth.saturating_sub(1)
        ),
        other => format!("{}, max depth {}", other.name(), i.max_depth),
    };
    let _ = writeln!(
        s,
        "integrator   {runs} (file asks for \"{}\"), rr {:?} {}",
        i.requested, i.rr_strategy, i.rr_continue_prob
    );
    let _ = writeln!(
        s,
        "             --integrator bidirectional: eye depth {}, light depth {}, rr thresholds \
         {} (eye) {} (light)",
        i.max_depth, i.light_depth, i.eye_rr_threshold, i.light_rr_threshold,
    );
    if let Some(why) = transport_reason(&i.requested, transport, d.delta_caustics()) {
        let _ = writeln!(s, "             {why}");
    }
    let spp = d
        .sampler
        .pixel_samples
        .map_or("not given".to_string(), |n| n.to_string());
    let _ = writeln!(
        s,
        "sampler      \"{}\", pixelsamples {spp}",
        d.sampler.requested
    );

    let triangles: usize = d
        .shapes
        .iter()
        .map(|sh| match &sh.geometry {
            Geometry::Mesh(m) => m.indices.len(),
            _ => 0,
        })
        .sum();
    let shape_kinds = counts(d.shapes.iter().map(|sh| sh.geometry.name()));
    let _ = writeln!(
        s,
        "shapes       {} ({shape_kinds}), {triangles} triangles",
        d.shapes.len()
    );
    let emitters = d.shapes.iter().filter(|sh| sh.area_light.is_some()).count();
    let lights = counts(
        d.lights
            .iter()
            .map(|l| match l {
                LightDesc::Infinite(i) if i.map.is_some() => "infinite (map)",
                l => l.name(),
            })
            .chain(std::iter::repeat_n("area (shapes)", emitters)),
    );
    let _ = writeln!(s, "lights       {lights}");
    if let Some(groups) = light_groups(&f.light_groups) {
        let _ = writeln!(s, "light groups {groups}");
    }
    let materials = counts(d.materials.iter().map(|m| m.name()));
    let _ = writeln!(s, "materials    {} ({materials})", d.materials.len());
    let _ = writeln!(s, "textures     {}", d.textures.len());
    let assets = counts(d.assets.iter().map(|a| match a.kind {
        AssetKind::Include => "include",
        AssetKind::Ply => "ply",
        AssetKind::Image => "image",
        AssetKind::Nk => "nk",
        AssetKind::Spectrum => "spectrum",
    }));
    let _ = writeln!(s, "assets       {} ({assets})", d.assets.len());
    let _ = writeln!(s, "parse time   {:.1} ms", seconds * 1e3);
    s
}
