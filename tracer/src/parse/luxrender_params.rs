//! LuxRender 1.x's parameters, plugin by plugin, and what YAT does with each: the table
//! [`verdict`] reads to say what `yat check` reports about a parameter.
//!
//! The plugins of the option statements (`Film`, `Sampler`, `SurfaceIntegrator`,
//! `VolumeIntegrator`, `Camera`, `Accelerator`, `Renderer`, `PixelFilter`) are listed whole:
//! every parameter their Create function reads in LuxRender 1.x's source (directly, or through
//! the light-sampling hints and the base sampler they create), with its default there. Of the
//! world statements (materials, lights, textures, shapes), only the parameters exporters write
//! that YAT's readers leave unread are listed; their readers' own tables list the rest.
//!
//! What `yat check` says about a parameter of a statement ([`verdict`]):
//! - [`Handling::Rendered`]: nothing, when YAT's reader consumed it (it renders it as LuxRender
//!   does, or reports itself where it does not); left unread, it is an unknown parameter.
//! - [`Handling::NoEffect`]: "no effect on the image", with its reason, whether or not a reader
//!   marked it read (readers pass over such parameters without a word).
//! - [`Handling::Differs`]: "not rendered as LuxRender would", unless the statement is one where
//!   it changes nothing: at LuxRender's default, which YAT renders (a note), or without the
//!   parameter that enables what it adjusts (no effect).
//! - [`Handling::Replaced`]: nothing: the plugin is rendered with another, and its statement's
//!   own warning says so.
//! - [`Handling::Ignored`]: LuxRender never reads it, nor does YAT: a note.
//! - Not in the table and not read by YAT: "unknown parameter ... ignored", a difference (it
//!   may be one LuxRender reads).

use crate::diag::Severity;
use crate::parse::params::{Param, ParamList, Values};
use Handling::{Rendered, Replaced};
use LuxDefault::{Bool, Derived, Float, Floats, Int, Text, Unset};

/// The statement kinds whose plugins the table lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Statement {
    Film,
    Sampler,
    SurfaceIntegrator,
    VolumeIntegrator,
    Camera,
    Accelerator,
    Renderer,
    PixelFilter,
    Material,
    LightSource,
    AreaLightSource,
    Texture,
    Shape,
}

impl Statement {
    /// The keyword as written in a scene file.
    pub fn keyword(self) -> &'static str {
        match self {
            Statement::Film => "Film",
            Statement::Sampler => "Sampler",
            Statement::SurfaceIntegrator => "SurfaceIntegrator",
            Statement::VolumeIntegrator => "VolumeIntegrator",
            Statement::Camera => "Camera",
            Statement::Accelerator => "Accelerator",
            Statement::Renderer => "Renderer",
            Statement::PixelFilter => "PixelFilter",
            Statement::Material => "Material",
            Statement::LightSource => "LightSource",
            Statement::AreaLightSource => "AreaLightSource",
            Statement::Texture => "Texture",
            Statement::Shape => "Shape",
        }
    }
}

/// LuxRender's default for a parameter, as its plugin's Create function has it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LuxDefault {
    Bool(bool),
    Int(i32),
    Float(f32),
    Floats(&'static [f32]),
    Text(&'static str),
    /// Computed from other settings (what from), and a value of that kind.
    Derived(&'static str, &'static LuxDefault),
    /// No value: absent, the parameter does nothing (or the plugin never reads it).
    Unset,
}

impl LuxDefault {
    /// Whether `values`, as a file gives them, are this default.
    fn is(&self, values: &Values) -> bool {
        match (self, values) {
            (LuxDefault::Bool(b), Values::Strings(v)) => {
                v.len() == 1 && v[0] == if *b { "true" } else { "false" }
            }
            (LuxDefault::Int(i), Values::Numbers(v)) => v.len() == 1 && v[0] == f64::from(*i),
            // Exporters write a float's f32 value in 15 decimals: compared as f32.
            (LuxDefault::Float(f), Values::Numbers(v)) => v.len() == 1 && v[0] as f32 == *f,
            (LuxDefault::Floats(fs), Values::Numbers(v)) => {
                v.len() == fs.len() && v.iter().zip(fs.iter()).all(|(a, b)| *a as f32 == *b)
            }
            (LuxDefault::Text(t), Values::Strings(v)) => v.len() == 1 && v[0] == *t,
            _ => false,
        }
    }
}

/// Why a parameter LuxRender reads leaves its image as it would be without it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoEffect {
    Sampler,
    LightSampling,
    Accelerator,
    Renderer,
    Output,
    Progress,
    Debug,
    Shutter,
    VolumeMarching,
}

impl NoEffect {
    pub fn reason(self) -> &'static str {
        match self {
            NoEffect::Sampler => "sampler choice: YAT's own samples converge to the same image",
            NoEffect::LightSampling => {
                "light sampling choice: YAT's own light samples converge to the same image"
            }
            NoEffect::Accelerator => "accelerator choice: it finds the same hits, sooner or later",
            NoEffect::Renderer => {
                "renderer choice: threads, devices and engines change how fast the image \
                 converges, not what it converges to"
            }
            NoEffect::Output => "output settings: which files are written, not what they show",
            NoEffect::Progress => {
                "progress settings: when the image is shown, saved or tested, not what it shows"
            }
            NoEffect::Debug => {
                "debug settings: what LuxRender logs or writes on the side, not what it renders"
            }
            NoEffect::Shutter => {
                "shutter times: they only time motion blur, which YAT reports where the scene \
                 has motion"
            }
            NoEffect::VolumeMarching => {
                "ray-marching step: it only samples volume regions, which YAT reports at each \
                 Volume statement"
            }
        }
    }
}

/// A parameter of the same statement that enables what another one adjusts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trigger {
    /// `name` has this value.
    Is(&'static str, &'static str),
    /// `name` is given with a value that is not empty.
    Given(&'static str),
}

impl Trigger {
    fn holds(self, params: &ParamList) -> bool {
        // Looked at without marking it read: only its reader does that.
        let value = |name: &str| match params.params.iter().rev().find(|p| p.name == name) {
            Some(Param {
                values: Values::Strings(v),
                ..
            }) => v.first().cloned(),
            _ => None,
        };
        match self {
            Trigger::Is(name, wanted) => value(name).is_some_and(|v| v == wanted),
            Trigger::Given(name) => value(name).is_some_and(|v| !v.is_empty()),
        }
    }

    fn describe(self) -> String {
        match self {
            Trigger::Is(name, value) => format!("\"{name}\" \"{value}\""),
            Trigger::Given(name) => format!("\"{name}\""),
        }
    }
}

/// Where a parameter that YAT ignores leaves LuxRender's image as YAT renders it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unless {
    /// Nowhere: any value changes LuxRender's image from YAT's.
    Never,
    /// At LuxRender's default, which is what YAT renders.
    Default,
    /// Where the statement has none of these, which enable what the parameter adjusts.
    Untriggered(&'static [Trigger]),
}

/// What YAT does with a parameter (see the module's rules).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Handling {
    /// YAT's reader reads it as LuxRender does, or reports itself where it renders otherwise.
    Rendered,
    /// LuxRender reads it and nothing in its image depends on it.
    NoEffect(NoEffect),
    /// LuxRender's image depends on it (`why`: how, and what YAT does instead) and YAT ignores
    /// it, except where `unless` holds.
    Differs { why: &'static str, unless: Unless },
    /// It shapes only a plugin YAT renders with another in its place, whose statement's
    /// warning says so.
    Replaced,
    /// LuxRender 1.x's plugin never reads it; `hint` says what it reads in its place.
    Ignored { hint: Option<&'static str> },
}

/// One of a plugin's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuxParam {
    pub name: &'static str,
    pub default: LuxDefault,
    pub handling: Handling,
}

/// A plugin (`Film "fleximage"`), its parameters in groups (groups are shared by plugins that
/// read the same parameters the same way).
#[derive(Debug)]
pub struct Plugin {
    pub statement: Statement,
    pub name: &'static str,
    pub groups: &'static [&'static [LuxParam]],
}

impl Plugin {
    pub fn params(&self) -> impl Iterator<Item = &'static LuxParam> {
        self.groups.iter().flat_map(|g| g.iter())
    }

    fn param(&self, name: &str) -> Option<&'static LuxParam> {
        self.params().find(|p| p.name == name)
    }
}

/// The plugin a statement's label (`Film "fleximage"`, as parameter lists are labelled)
/// names, if the table lists it.
pub fn plugin(label: &str) -> Option<&'static Plugin> {
    let (keyword, quoted) = label.split_once(' ')?;
    let name = quoted.strip_prefix('"')?.strip_suffix('"')?;
    PLUGINS
        .iter()
        .find(|p| p.statement.keyword() == keyword && p.name == name)
}

/// What `yat check` reports about a parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    pub severity: Severity,
    pub message: String,
}

/// What to report about parameter `p` of the statement whose parameters are `params`, after
/// its reader read them; None when there is nothing to say.
pub fn verdict(params: &ParamList, p: &Param) -> Option<Verdict> {
    let statement = &params.statement;
    let decl = p.decl();
    // Formatted only for a report: most parameters have nothing to say.
    let given = || format!("\"{decl}\" {}", shown(&p.values));
    let report = |severity, message| Some(Verdict { severity, message });
    let without_effect = |reason: &str| {
        report(
            Severity::NoEffect,
            format!(
                "{statement}: {}: no effect on the image ({reason})",
                given()
            ),
        )
    };
    let unknown = || {
        report(
            Severity::Differs,
            format!("{statement}: unknown parameter \"{decl}\" ignored"),
        )
    };
    let Some(entry) = plugin(statement).and_then(|plugin| plugin.param(&p.name)) else {
        return if p.is_used() { None } else { unknown() };
    };
    match entry.handling {
        Handling::Rendered if p.is_used() => None,
        Handling::Rendered => unknown(),
        Handling::NoEffect(why) => without_effect(why.reason()),
        Handling::Differs { why, unless } => match unless {
            Unless::Default if entry.default.is(&p.values) => report(
                Severity::Note,
                format!(
                    "{statement}: {} is LuxRender's default, which YAT renders",
                    given()
                ),
            ),
            Unless::Untriggered(triggers) if !triggers.iter().any(|t| t.holds(params)) => {
                let enablers: Vec<String> = triggers.iter().map(|t| t.describe()).collect();
                without_effect(&format!("only with {}", enablers.join(" or ")))
            }
            _ => report(
                Severity::Differs,
                format!("{statement}: {} is not rendered: {why}", given()),
            ),
        },
        Handling::Replaced => None,
        Handling::Ignored { .. } if p.is_used() => None,
        Handling::Ignored { hint } => {
            let hint = hint.map_or(String::new(), |h| format!(" ({h})"));
            report(
                Severity::Note,
                format!("{statement}: \"{decl}\" is ignored, as LuxRender ignores it{hint}"),
            )
        }
    }
}

/// Values as a person reads them, `[0.4]` or `["cut"]`; long lists are cut short.
fn shown(values: &Values) -> String {
    const SHOWN: usize = 4;
    let (count, mut items): (usize, Vec<String>) = match values {
        Values::Numbers(v) => (
            v.len(),
            v.iter()
                .take(SHOWN)
                .map(|&x| {
                    let x = x as f32;
                    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
                        format!("{x:e}")
                    } else {
                        format!("{x}")
                    }
                })
                .collect(),
        ),
        Values::Strings(v) => (
            v.len(),
            v.iter().take(SHOWN).map(|s| format!("\"{s}\"")).collect(),
        ),
    };
    if count > SHOWN {
        items.push("...".into());
    }
    format!("[{}]", items.join(" "))
}

// ---------------------------------------------------------------------------------------------
// The table.

const fn param(name: &'static str, default: LuxDefault, handling: Handling) -> LuxParam {
    LuxParam {
        name,
        default,
        handling,
    }
}

const fn no_effect(name: &'static str, default: LuxDefault, why: NoEffect) -> LuxParam {
    param(name, default, Handling::NoEffect(why))
}

/// YAT ignores it; the same image at LuxRender's default.
const fn differs(name: &'static str, default: LuxDefault, why: &'static str) -> LuxParam {
    param(
        name,
        default,
        Handling::Differs {
            why,
            unless: Unless::Default,
        },
    )
}

/// YAT ignores it; no effect without one of `triggers`.
const fn differs_with(
    name: &'static str,
    default: LuxDefault,
    triggers: &'static [Trigger],
    why: &'static str,
) -> LuxParam {
    param(
        name,
        default,
        Handling::Differs {
            why,
            unless: Unless::Untriggered(triggers),
        },
    )
}

const fn ignored(name: &'static str, hint: Option<&'static str>) -> LuxParam {
    param(name, Unset, Handling::Ignored { hint })
}

/// LuxRender's film, `film/fleximage.cpp`'s CreateFilm; also what it reads a "multiimage" as.
const FLEXIMAGE: &[LuxParam] = &[
    param("xresolution", Int(800), Rendered),
    param("yresolution", Int(600), Rendered),
    differs(
        "cropwindow",
        Floats(&[0.0, 1.0, 0.0, 1.0]),
        "LuxRender renders only this part of the film; YAT renders all of it",
    ),
    differs(
        "premultiplyalpha",
        Bool(false),
        "LuxRender multiplies each sample by its alpha, which blackens the environment camera \
         rays see; YAT keeps it",
    ),
    differs(
        "filterquality",
        Int(4),
        "LuxRender tabulates the pixel filter in 2^filterquality steps; YAT's table is fixed, \
         finer than the default's 16",
    ),
    // The files written and how (`film/outputs.rs`); ldr_clamp_method limits the PNG's and
    // TGA's bright colours, as LuxRender's ColorSystem::Limit does before the gamma.
    param("ldr_clamp_method", Text("cut"), Rendered),
    param("write_exr", Bool(false), Rendered),
    param("write_exr_channels", Text("RGB"), Rendered),
    param("write_exr_halftype", Bool(true), Rendered),
    no_effect(
        "write_exr_compressiontype",
        Text("PIZ (lossless)"),
        NoEffect::Output,
    ),
    param("write_exr_applyimaging", Bool(true), Rendered),
    // The three gamut clamps are stored by LuxRender 1.x's film and never applied: the PNG's
    // pixels are limited by ldr_clamp_method alone, whatever these say.
    no_effect("write_exr_gamutclamp", Bool(true), NoEffect::Output),
    param("write_exr_ZBuf", Bool(false), Rendered),
    differs(
        "write_exr_zbuf_normalizationtype",
        Text("None"),
        "LuxRender rescales the EXR's Z channel to the camera's clipping range or the depths' \
         range; YAT writes the camera distances, as \"None\" does",
    ),
    param("write_exr_straightcolors", Bool(false), Rendered),
    param("write_png", Bool(true), Rendered),
    param("write_png_channels", Text("RGB"), Rendered),
    param("write_png_16bit", Bool(false), Rendered),
    no_effect("write_png_gamutclamp", Bool(true), NoEffect::Output),
    no_effect("write_png_ZBuf", Bool(false), NoEffect::Output),
    no_effect(
        "write_png_zbuf_normalizationtype",
        Text("Min/Max"),
        NoEffect::Output,
    ),
    param("write_tga", Bool(false), Rendered),
    param("write_tga_channels", Text("RGB"), Rendered),
    no_effect("write_tga_gamutclamp", Bool(true), NoEffect::Output),
    no_effect("write_tga_ZBuf", Bool(false), NoEffect::Output),
    no_effect(
        "write_tga_zbuf_normalizationtype",
        Text("Min/Max"),
        NoEffect::Output,
    ),
    no_effect("write_resume_flm", Bool(false), NoEffect::Output),
    no_effect("restart_resume_flm", Bool(false), NoEffect::Output),
    no_effect("write_flm_direct", Bool(false), NoEffect::Output),
    param("filename", Text("luxout"), Rendered),
    no_effect("writeinterval", Int(60), NoEffect::Progress),
    no_effect(
        "flmwriteinterval",
        Derived("writeinterval", &Int(60)),
        NoEffect::Progress,
    ),
    no_effect("displayinterval", Int(12), NoEffect::Progress),
    param("outlierrejection_k", Int(0), Rendered),
    no_effect("debug", Bool(false), NoEffect::Debug),
    param("haltspp", Int(-1), Rendered),
    param("halttime", Int(-1), Rendered),
    param("haltthreshold", Float(-1.0), Rendered),
    param("convergencestep", Float(32.0), Rendered),
    // Set by LuxRender's network slaves: they leave the noise-aware sampling map to the master.
    no_effect("disable_noisemap_update", Bool(false), NoEffect::Sampler),
    no_effect("usersamplingmap_filename", Text(""), NoEffect::Sampler),
    // XYZ to RGB: YAT renders in RGB, taken as LuxRender's default primaries and white.
    differs(
        "colorspace_red",
        Floats(&[0.63, 0.34]),
        "LuxRender's RGB has these primaries; YAT's has LuxRender's default ones",
    ),
    differs(
        "colorspace_green",
        Floats(&[0.31, 0.595]),
        "LuxRender's RGB has these primaries; YAT's has LuxRender's default ones",
    ),
    differs(
        "colorspace_blue",
        Floats(&[0.155, 0.07]),
        "LuxRender's RGB has these primaries; YAT's has LuxRender's default ones",
    ),
    differs(
        "colorspace_white",
        Floats(&[0.314275, 0.329411]),
        "LuxRender's RGB has this white point; YAT's has LuxRender's default one",
    ),
    param("tonemapkernel", Text("autolinear"), Rendered),
    param("reinhard_prescale", Float(1.0), Rendered),
    param("reinhard_postscale", Float(1.0), Rendered),
    param("reinhard_burn", Float(6.0), Rendered),
    param("linear_sensitivity", Float(50.0), Rendered),
    param("linear_exposure", Float(1.0), Rendered),
    param("linear_fstop", Float(2.8), Rendered),
    // The linear kernel exposes for mid-grey with (118/255)^linear_gamma.
    param("linear_gamma", Float(1.0), Rendered),
    param("contrast_ywa", Float(1.0), Rendered),
    // The falsecolors kernel's, which YAT's film reports as unknown where it is chosen.
    param("false_method", Text("linear"), Rendered),
    param("false_colorscale", Text("std"), Rendered),
    param("false_max", Float(0.0), Rendered),
    param("false_min", Float(0.0), Rendered),
    differs(
        "cameraresponse",
        Text(""),
        "LuxRender maps the image through this camera's response curves; YAT does not",
    ),
    param("gamma", Float(2.2), Rendered),
    // Film tiles, each filled by one thread at a time.
    no_effect("tilecount", Int(0), NoEffect::Renderer),
    differs(
        "bloom_enabled",
        Bool(false),
        "LuxRender adds a glow around bright pixels; YAT does not",
    ),
    differs_with("bloom_radius", Float(0.07), BLOOM, "YAT adds no bloom"),
    differs_with("bloom_weight", Float(0.25), BLOOM, "YAT adds no bloom"),
    differs(
        "vignetting_enabled",
        Bool(false),
        "LuxRender darkens the image towards its corners; YAT does not",
    ),
    differs_with(
        "vignetting_scale",
        Float(0.4),
        VIGNETTING,
        "YAT adds no vignetting",
    ),
    differs(
        "abberation_enabled",
        Bool(false),
        "LuxRender shifts the colours apart towards the image's edges; YAT does not",
    ),
    differs_with(
        "abberation_amount",
        Float(0.005),
        ABERRATION,
        "YAT adds no chromatic aberration",
    ),
    differs(
        "glare_enabled",
        Bool(false),
        "LuxRender adds glare streaks around bright pixels; YAT does not",
    ),
    differs_with("glare_amount", Float(0.03), GLARE, "YAT adds no glare"),
    differs_with("glare_radius", Float(0.03), GLARE, "YAT adds no glare"),
    differs_with("glare_blades", Int(3), GLARE, "YAT adds no glare"),
    differs_with("glare_threshold", Float(0.5), GLARE, "YAT adds no glare"),
    differs_with("glarelashesfilename", Text(""), GLARE, "YAT adds no glare"),
    differs_with("glarepupilfilename", Text(""), GLARE, "YAT adds no glare"),
];

const BLOOM: &[Trigger] = &[Trigger::Is("bloom_enabled", "true")];
const VIGNETTING: &[Trigger] = &[Trigger::Is("vignetting_enabled", "true")];
const ABERRATION: &[Trigger] = &[Trigger::Is("abberation_enabled", "true")];
const GLARE: &[Trigger] = &[Trigger::Is("glare_enabled", "true")];

/// LuxRender 0.x's multiimage film's own parameters (its last source, removed in 2008, and the
/// 0.5 fleximage's output switches): LuxRender 1.x reads a "multiimage" film with fleximage's
/// reader, which reads none of them.
const MULTIIMAGE: &[LuxParam] = &[
    ignored("hdr_filename", Some(MULTI_FILES)),
    ignored("igi_filename", Some(MULTI_FILES)),
    ignored("ldr_filename", Some(MULTI_FILES)),
    ignored("hdr_writeinterval", Some(MULTI_WRITEINTERVAL)),
    ignored("igi_writeinterval", Some(MULTI_WRITEINTERVAL)),
    ignored("ldr_writeinterval", Some(MULTI_WRITEINTERVAL)),
    ignored(
        "ldr_displayinterval",
        Some("LuxRender 1.x reads multiimage as fleximage, whose is displayinterval"),
    ),
    ignored(
        "tonemapper",
        Some("LuxRender 1.x reads multiimage as fleximage, whose is tonemapkernel"),
    ),
    ignored(
        "contrast_displayadaptationY",
        Some("LuxRender 1.x reads multiimage as fleximage, whose is contrast_ywa"),
    ),
    ignored(
        "nonlinear_maxY",
        Some("LuxRender 1.x reads multiimage as fleximage, which has no nonlinear kernel"),
    ),
    ignored(
        "bloomwidth",
        Some("LuxRender 1.x reads multiimage as fleximage, whose is bloom_weight"),
    ),
    ignored(
        "bloomradius",
        Some("LuxRender 1.x reads multiimage as fleximage, whose is bloom_radius"),
    ),
    ignored(
        "dither",
        Some("LuxRender 1.x reads multiimage as fleximage, which does not dither"),
    ),
    ignored("write_tonemapped_exr", Some(MULTI_FILES)),
    ignored("write_untonemapped_exr", Some(MULTI_FILES)),
    ignored("write_tonemapped_igi", Some(MULTI_FILES)),
    ignored("write_untonemapped_igi", Some(MULTI_FILES)),
    ignored("write_tonemapped_tga", Some(MULTI_FILES)),
];

const MULTI_FILES: &str =
    "LuxRender 1.x reads multiimage as fleximage, whose files are chosen by write_exr, write_png \
     and write_tga";
const MULTI_WRITEINTERVAL: &str =
    "LuxRender 1.x reads multiimage as fleximage, whose is writeinterval";

const NOISE_AWARE: &[LuxParam] = &[no_effect("noiseaware", Bool(false), NoEffect::Sampler)];

/// `samplers/random.cpp`, also the base sampler erpt creates by default.
const RANDOM: &[LuxParam] = &[
    param("pixelsamples", Int(4), Rendered),
    no_effect("xsamples", Int(-1), NoEffect::Sampler),
    no_effect("ysamples", Int(-1), NoEffect::Sampler),
    no_effect("pixelsampler", Text("vegas"), NoEffect::Sampler),
];

const LOWDISCREPANCY: &[LuxParam] = &[
    param("pixelsamples", Int(4), Rendered),
    no_effect("pixelsampler", Text("vegas"), NoEffect::Sampler),
];

const METROPOLIS: &[LuxParam] = &[
    no_effect("maxconsecrejects", Int(512), NoEffect::Sampler),
    no_effect("largemutationprob", Float(0.4), NoEffect::Sampler),
    no_effect("usevariance", Bool(false), NoEffect::Sampler),
    no_effect("usecooldown", Bool(true), NoEffect::Sampler),
    no_effect(
        "mutationrange",
        Derived("(xresolution + yresolution) / 32", &Float(43.75)),
        NoEffect::Sampler,
    ),
];

const ERPT: &[LuxParam] = &[
    no_effect("chainlength", Int(100), NoEffect::Sampler),
    no_effect(
        "mutationrange",
        Derived("(xresolution + yresolution) / 50", &Float(28.0)),
        NoEffect::Sampler,
    ),
    no_effect("basesampler", Text("random"), NoEffect::Sampler),
];

/// The light-sampling hints (core/renderinghints.cpp) path, directlighting, exphotonmap, sppm
/// and bidirectional read; `strategy` is the older name of `lightstrategy`.
const LIGHT_HINTS: &[LuxParam] = &[
    no_effect("shadowraycount", Int(1), NoEffect::LightSampling),
    no_effect(
        "lightstrategy",
        Derived("strategy, else \"auto\"", &Text("auto")),
        NoEffect::LightSampling,
    ),
    no_effect("strategy", Text("auto"), NoEffect::LightSampling),
];

const PATH: &[LuxParam] = &[
    param("maxdepth", Int(16), Rendered),
    param("rrcontinueprob", Float(0.65), Rendered),
    param("rrstrategy", Text("efficiency"), Rendered),
    param("includeenvironment", Bool(true), Rendered),
    differs(
        "directlightsampling",
        Bool(true),
        "without it LuxRender's paths find lamps only by hitting them, so point, spot and \
         distant lights light nothing; YAT always samples the lamps",
    ),
];

const DIRECTLIGHTING: &[LuxParam] = &[param("maxdepth", Int(5), Rendered)];

const BIDIRECTIONAL: &[LuxParam] = &[
    param("eyedepth", Int(8), Rendered),
    param("lightdepth", Int(8), Rendered),
    param("eyerrthreshold", Float(0.0), Rendered),
    param("lightrrthreshold", Float(0.0), Rendered),
    no_effect("lightraycount", Int(1), NoEffect::LightSampling),
    no_effect(
        "lightpathstrategy",
        Derived("strategy, else \"auto\"", &Text("auto")),
        NoEffect::LightSampling,
    ),
    // Multiple importance sampling in the hybrid renderer's bidirectional paths: weights.
    no_effect("hybridusemis", Bool(false), NoEffect::LightSampling),
    // The eye and light buffers written as images of their own.
    no_effect("debug", Bool(false), NoEffect::Debug),
];

const DISTRIBUTEDPATH: &[LuxParam] = &[
    param("directsampleall", Bool(true), Replaced),
    param("directsamples", Int(1), Replaced),
    param("directdiffuse", Bool(true), Replaced),
    param("directglossy", Bool(true), Replaced),
    param("indirectsampleall", Bool(false), Replaced),
    param("indirectsamples", Int(1), Replaced),
    param("indirectdiffuse", Bool(true), Replaced),
    param("indirectglossy", Bool(true), Replaced),
    param("diffusereflectdepth", Int(3), Replaced),
    param("diffusereflectsamples", Int(1), Replaced),
    param("diffuserefractdepth", Int(5), Replaced),
    param("diffuserefractsamples", Int(1), Replaced),
    param("glossyreflectdepth", Int(2), Replaced),
    param("glossyreflectsamples", Int(1), Replaced),
    param("glossyrefractdepth", Int(5), Replaced),
    param("glossyrefractsamples", Int(1), Replaced),
    param("specularreflectdepth", Int(2), Replaced),
    param("specularrefractdepth", Int(5), Replaced),
    no_effect("strategy", Text("auto"), NoEffect::LightSampling),
    param("diffusereflectreject", Bool(false), Replaced),
    param("diffusereflectreject_threshold", Float(10.0), Replaced),
    param("diffuserefractreject", Bool(false), Replaced),
    param("diffuserefractreject_threshold", Float(10.0), Replaced),
    param("glossyreflectreject", Bool(false), Replaced),
    param("glossyreflectreject_threshold", Float(10.0), Replaced),
    param("glossyrefractreject", Bool(false), Replaced),
    param("glossyrefractreject_threshold", Float(10.0), Replaced),
];

const EXPHOTONMAP: &[LuxParam] = &[
    param("maxdepth", Int(5), Replaced),
    param("maxphotondepth", Int(10), Replaced),
    param("directphotons", Int(200000), Replaced),
    param("causticphotons", Int(20000), Replaced),
    param("indirectphotons", Int(200000), Replaced),
    param("radiancephotons", Int(200000), Replaced),
    param("nphotonsused", Int(50), Replaced),
    param("maxphotondist", Float(0.5), Replaced),
    param("finalgather", Bool(true), Replaced),
    param("finalgathersamples", Int(32), Replaced),
    param("renderingmode", Text("directlighting"), Replaced),
    param("gatherangle", Float(10.0), Replaced),
    param("rrstrategy", Text("efficiency"), Replaced),
    param("rrcontinueprob", Float(0.65), Replaced),
    param(
        "distancethreshold",
        Derived("1.25 x maxphotondist", &Float(0.625)),
        Replaced,
    ),
    param("photonmapsfile", Text(""), Replaced),
    param("dbg_enabledirect", Bool(true), Replaced),
    param("dbg_enableradiancemap", Bool(false), Replaced),
    param("dbg_enableindircaustic", Bool(true), Replaced),
    param("dbg_enableindirdiffuse", Bool(true), Replaced),
    param("dbg_enableindirspecular", Bool(true), Replaced),
];

const IGI: &[LuxParam] = &[
    param("nsets", Int(4), Replaced),
    param("nlights", Int(64), Replaced),
    param("maxdepth", Int(5), Replaced),
    param("mindist", Float(0.1), Replaced),
    param("glimit", Derived("1 / mindist", &Float(10.0)), Replaced),
];

/// `integrators/sppm.cpp` (its startk and drawing switches are commented out in 1.x).
const SPPM: &[LuxParam] = &[
    param("photonsampler", Text("halton"), Replaced),
    param("lookupaccel", Text("hybridhashgrid"), Replaced),
    param("pixelsampler", Text("hilbert"), Replaced),
    param("maxeyedepth", Int(16), Replaced),
    param("alpha", Float(0.7), Replaced),
    param("startradius", Float(2.0), Replaced),
    param("maxphotondepth", Int(16), Replaced),
    param("parallelhashgridspare", Float(1.0), Replaced),
    param("photonperpass", Int(1000000), Replaced),
    param("hitpointperpass", Int(0), Replaced),
    param("includeenvironment", Bool(true), Replaced),
    param("directlightsampling", Bool(true), Replaced),
    param("useproba", Bool(true), Replaced),
    param("wavelengthstratificationpasses", Int(8), Replaced),
    no_effect("debug", Bool(false), NoEffect::Debug),
    param("storeglossy", Bool(false), Replaced),
];

const STEPSIZE: &[LuxParam] = &[no_effect("stepsize", Float(1.0), NoEffect::VolumeMarching)];

/// Every camera's shutter, read by each camera and by core/context.cpp for endtransform.
const SHUTTER: &[LuxParam] = &[
    no_effect("shutteropen", Float(0.0), NoEffect::Shutter),
    no_effect("shutterclose", Float(1.0), NoEffect::Shutter),
    no_effect("shutterdistribution", Text("uniform"), NoEffect::Shutter),
];

const END_TRANSFORM: &str =
    "LuxRender moves the camera to this coordinate system while the shutter is open (motion \
     blur); YAT renders it still";

/// What the perspective and orthographic cameras read alike (and YAT's fisheye).
const PROJECTIVE: &[LuxParam] = &[
    param("hither", Float(1e-3), Rendered),
    param("yon", Float(1e30), Rendered),
    differs("endtransform", Text(""), END_TRANSFORM),
    param("lensradius", Float(0.0), Rendered),
    param("focaldistance", Float(1e30), Rendered),
    param("autofocus", Bool(false), Rendered),
    param(
        "frameaspectratio",
        Derived("xresolution / yresolution", &Float(1.5)),
        Rendered,
    ),
    param(
        "screenwindow",
        Derived(
            "the longer axis over [-aspect, aspect], the shorter over [-1, 1]",
            &Floats(&[-1.5, 1.5, -1.0, 1.0]),
        ),
        Rendered,
    ),
];

const FOV: &[LuxParam] = &[param("fov", Float(90.0), Rendered)];

const PERSPECTIVE: &[LuxParam] = &[
    param("blades", Int(0), Rendered),
    param("power", Int(3), Rendered),
    param("distribution", Text("uniform"), Rendered),
    // Read only to warn that it is LuxCore's: LuxRender's own renderers do not clip.
    ignored(
        "clippingplane",
        Some("LuxRender 1.x clips with it under its luxcore renderer only"),
    ),
];

const ENVIRONMENT: &[LuxParam] = &[
    param("hither", Float(1e-3), Replaced),
    param("yon", Float(1e30), Replaced),
    param("endtransform", Text(""), Replaced),
    param("lensradius", Float(0.0), Replaced),
    param("focaldistance", Float(1e30), Replaced),
    param(
        "frameaspectratio",
        Derived("xresolution / yresolution", &Float(1.5)),
        Replaced,
    ),
    param(
        "screenwindow",
        Derived("[-aspect, aspect, -1, 1]", &Floats(&[-1.5, 1.5, -1.0, 1.0])),
        Replaced,
    ),
];

const REALISTIC: &[LuxParam] = &[
    param("hither", Float(1e-3), Replaced),
    param("yon", Float(1e30), Replaced),
    param("endtransform", Text(""), Replaced),
    param("aperture_diameter", Float(1.0), Replaced),
    param("filmdiag", Float(35.0), Replaced),
    param("filmdistance", Float(70.0), Replaced),
    param("specfile", Text(""), Replaced),
];

const BVH: &[LuxParam] = &[
    no_effect("treetype", Int(4), NoEffect::Accelerator),
    no_effect("costsamples", Int(0), NoEffect::Accelerator),
    no_effect("intersectcost", Int(80), NoEffect::Accelerator),
    no_effect("traversalcost", Int(10), NoEffect::Accelerator),
    no_effect("emptybonus", Float(0.5), NoEffect::Accelerator),
];

const QBVH: &[LuxParam] = &[
    no_effect("maxprimsperleaf", Int(4), NoEffect::Accelerator),
    no_effect(
        "fullsweepthreshold",
        Derived("4 x maxprimsperleaf", &Int(16)),
        NoEffect::Accelerator,
    ),
    no_effect("skipfactor", Int(1), NoEffect::Accelerator),
];

const SQBVH: &[LuxParam] = &[no_effect("alpha", Float(1e-5), NoEffect::Accelerator)];

/// `accelerators/tabreckdtree.cpp` and `unsafekdtree.cpp` alike.
const KDTREE: &[LuxParam] = &[
    no_effect("intersectcost", Int(80), NoEffect::Accelerator),
    no_effect("traversalcost", Int(1), NoEffect::Accelerator),
    no_effect("emptybonus", Float(0.5), NoEffect::Accelerator),
    no_effect("maxprims", Int(1), NoEffect::Accelerator),
    no_effect("maxdepth", Int(-1), NoEffect::Accelerator),
];

/// The hybrid renderer: the sampler renderer tracing its rays on OpenCL devices.
const HYBRID: &[LuxParam] = &[
    no_effect("configfile", Text(""), NoEffect::Renderer),
    no_effect("raybuffersize", Int(8192), NoEffect::Renderer),
    no_effect("statebuffercount", Int(1), NoEffect::Renderer),
    no_effect("opencl.gpu.use", Bool(true), NoEffect::Renderer),
    no_effect("opencl.gpu.workgroup.size", Int(64), NoEffect::Renderer),
    no_effect("opencl.platform.index", Int(-1), NoEffect::Renderer),
    no_effect("opencl.devices.select", Text(""), NoEffect::Renderer),
    no_effect(
        "accelerator.qbvh.stacksize.max",
        Int(48),
        NoEffect::Renderer,
    ),
];

/// LuxCore's properties can set anything of its rendering (engine, depths, tone map).
const LUXCORE: &[LuxParam] = &[
    param(
        "config",
        Unset,
        Handling::Differs {
            why: "LuxCore's properties may change what LuxCore renders; YAT reads none",
            unless: Unless::Never,
        },
    ),
    differs(
        "localconfigfile",
        Text(""),
        "LuxCore's properties may change what LuxCore renders; YAT reads none",
    ),
];

/// The filters' half-widths, by their default.
const WIDTH_HALF: &[LuxParam] = &[
    param("xwidth", Float(0.5), Rendered),
    param("ywidth", Float(0.5), Rendered),
];
const WIDTH_2: &[LuxParam] = &[
    param("xwidth", Float(2.0), Rendered),
    param("ywidth", Float(2.0), Rendered),
];
const WIDTH_4: &[LuxParam] = &[
    param("xwidth", Float(4.0), Rendered),
    param("ywidth", Float(4.0), Rendered),
];

const MITCHELL: &[LuxParam] = &[
    param("B", Float(1.0 / 3.0), Rendered),
    param("C", Float(1.0 / 3.0), Rendered),
    param("supersample", Bool(false), Rendered),
];

/// LuxRender's Catmull-Rom keeps its two-pixel lobes at any width (a width only cuts it
/// off), where YAT stretches the filter over the width it is given.
const CATMULLROM_WIDTHS: &[LuxParam] = &[
    param(
        "xwidth",
        Float(4.0),
        Handling::Differs {
            why: CATMULLROM_WIDTH,
            unless: Unless::Never,
        },
    ),
    param(
        "ywidth",
        Float(4.0),
        Handling::Differs {
            why: CATMULLROM_WIDTH,
            unless: Unless::Never,
        },
    ),
];

const CATMULLROM_WIDTH: &str =
    "LuxRender's Catmull-Rom keeps its two-pixel lobes whatever the width; YAT stretches it over \
     the width (leave the width out for the same filter)";

/// What the world statements' LuxRender plugins read, or not, that YAT's readers leave unread.
const LIGHT_IMPORTANCE: &[LuxParam] =
    &[no_effect("importance", Float(1.0), NoEffect::LightSampling)];
const LIGHT_NSAMPLES: &[LuxParam] = &[no_effect("nsamples", Int(1), NoEffect::LightSampling)];
/// A point or area light's goniometric profile (lights/sphericalfunction), which flipz turns.
const LIGHT_PROFILE: &[LuxParam] = &[differs_with(
    "flipz",
    Bool(false),
    &[Trigger::Given("mapname"), Trigger::Given("iesname")],
    "YAT does not render a light's profile",
)];

/// `textures/imagemap.cpp`: the mip-map filters. YAT filters bilinearly, as LuxRender's
/// default; the anisotropy and the discarded levels only shape the mip-map filters.
const IMAGEMAP: &[LuxParam] = &[
    differs(
        "filtertype",
        Text("bilinear"),
        "LuxRender's mip-map filters blur texels seen from afar; YAT filters bilinearly",
    ),
    differs_with(
        "maxanisotropy",
        Float(8.0),
        &[Trigger::Is("filtertype", "mipmap_ewa")],
        "YAT filters bilinearly",
    ),
    differs_with(
        "discardmipmaps",
        Int(0),
        &[
            Trigger::Is("filtertype", "mipmap_trilinear"),
            Trigger::Is("filtertype", "mipmap_ewa"),
        ],
        "YAT filters bilinearly",
    ),
];

/// `shapes/mesh.cpp` and `plymesh.cpp`.
const MESH_TANGENTS: &[LuxParam] = &[differs(
    "generatetangents",
    Bool(false),
    "LuxRender then shades normal and bump maps in generated tangent frames; YAT keeps the \
     mesh's uv directions",
)];

/// Material parameters LuxRender's plugin does not read, written by exporters anyway.
const MIRROR_UNREAD: &[LuxParam] = &[
    // LuxRender's mirror reads Kr, film, filmindex and bumpmap only; LuxBlend writes a
    // mirror's glass-like index and a diffuse colour anyway.
    ignored("index", None),
    ignored("Kd", None),
];
/// pbrt's plastic and shinymetal had one `roughness`; LuxRender 1.x reads uroughness and
/// vroughness only (their defaults apply).
const ROUGHNESS_UNREAD: &[LuxParam] = &[ignored("roughness", None)];
/// Only LuxRender's glass has a thin film; its roughglass and glass2 read neither.
const FILM_UNREAD: &[LuxParam] = &[ignored("film", None), ignored("filmindex", None)];
/// LuxRender's glass2 reflects and transmits white, its index from its volumes.
const GLASS2_UNREAD: &[LuxParam] = &[
    ignored("Kr", None),
    ignored("Kt", None),
    ignored(
        "index",
        Some("glass2 takes its index from its Interior and Exterior volumes' fresnel"),
    ),
    ignored(
        "cauchyb",
        Some("glass2 disperses with its volumes' fresnel textures"),
    ),
];
/// LuxRender's glossy chooses its separable (Kd under a coating) or combined model with it.
const GLOSSY: &[LuxParam] = &[differs(
    "separable",
    Bool(true),
    "LuxRender renders a combined glossy model without it; YAT's glossy is the separable one",
)];

const fn plugin_of(
    statement: Statement,
    name: &'static str,
    groups: &'static [&'static [LuxParam]],
) -> Plugin {
    Plugin {
        statement,
        name,
        groups,
    }
}

/// Every plugin LuxRender 1.x registers for the option statements, under each name it
/// registers (aliases share their groups), YAT's fisheye camera, and the world statements'
/// plugins with parameters above.
pub static PLUGINS: &[Plugin] = &[
    plugin_of(Statement::Film, "fleximage", &[FLEXIMAGE]),
    // LuxRender 1.x registers "multiimage" as another name of fleximage (for older scenes).
    plugin_of(Statement::Film, "multiimage", &[FLEXIMAGE, MULTIIMAGE]),
    plugin_of(Statement::Sampler, "random", &[NOISE_AWARE, RANDOM]),
    plugin_of(
        Statement::Sampler,
        "lowdiscrepancy",
        &[NOISE_AWARE, LOWDISCREPANCY],
    ),
    plugin_of(Statement::Sampler, "metropolis", &[NOISE_AWARE, METROPOLIS]),
    // erpt reads its parameters and passes them all to its base sampler, random by default.
    plugin_of(Statement::Sampler, "erpt", &[ERPT, NOISE_AWARE, RANDOM]),
    plugin_of(Statement::Sampler, "sobol", &[NOISE_AWARE]),
    plugin_of(Statement::SurfaceIntegrator, "path", &[PATH, LIGHT_HINTS]),
    plugin_of(
        Statement::SurfaceIntegrator,
        "directlighting",
        &[DIRECTLIGHTING, LIGHT_HINTS],
    ),
    plugin_of(
        Statement::SurfaceIntegrator,
        "bidirectional",
        &[BIDIRECTIONAL, LIGHT_HINTS],
    ),
    plugin_of(
        Statement::SurfaceIntegrator,
        "distributedpath",
        &[DISTRIBUTEDPATH],
    ),
    plugin_of(
        Statement::SurfaceIntegrator,
        "exphotonmap",
        &[EXPHOTONMAP, LIGHT_HINTS],
    ),
    plugin_of(Statement::SurfaceIntegrator, "igi", &[IGI]),
    plugin_of(Statement::SurfaceIntegrator, "sppm", &[SPPM, LIGHT_HINTS]),
    plugin_of(Statement::VolumeIntegrator, "emission", &[STEPSIZE]),
    plugin_of(Statement::VolumeIntegrator, "single", &[STEPSIZE]),
    plugin_of(Statement::VolumeIntegrator, "multi", &[STEPSIZE]),
    plugin_of(Statement::VolumeIntegrator, "none", &[]),
    plugin_of(
        Statement::Camera,
        "perspective",
        &[SHUTTER, PROJECTIVE, FOV, PERSPECTIVE],
    ),
    plugin_of(Statement::Camera, "orthographic", &[SHUTTER, PROJECTIVE]),
    plugin_of(Statement::Camera, "environment", &[SHUTTER, ENVIRONMENT]),
    plugin_of(Statement::Camera, "realistic", &[SHUTTER, REALISTIC]),
    // YAT's own (the course's), not LuxRender's: it reads the perspective camera's parameters
    // but for the aperture.
    plugin_of(Statement::Camera, "fisheye", &[SHUTTER, PROJECTIVE, FOV]),
    plugin_of(Statement::Accelerator, "bvh", &[BVH]),
    plugin_of(Statement::Accelerator, "qbvh", &[QBVH]),
    plugin_of(Statement::Accelerator, "sqbvh", &[QBVH, SQBVH]),
    plugin_of(Statement::Accelerator, "tabreckdtree", &[KDTREE]),
    plugin_of(Statement::Accelerator, "kdtree", &[KDTREE]),
    plugin_of(Statement::Accelerator, "unsafekdtree", &[KDTREE]),
    plugin_of(Statement::Accelerator, "bruteforce", &[]),
    plugin_of(Statement::Accelerator, "none", &[]),
    plugin_of(Statement::Renderer, "sampler", &[]),
    plugin_of(Statement::Renderer, "hybrid", &[HYBRID]),
    plugin_of(Statement::Renderer, "hybridsampler", &[HYBRID]),
    plugin_of(Statement::Renderer, "sppm", &[]),
    plugin_of(Statement::Renderer, "luxcore", &[LUXCORE]),
    plugin_of(Statement::Renderer, "slg", &[LUXCORE]),
    plugin_of(Statement::PixelFilter, "box", &[WIDTH_HALF]),
    plugin_of(
        Statement::PixelFilter,
        "gaussian",
        &[WIDTH_2, &[param("alpha", Float(2.0), Rendered)]],
    ),
    plugin_of(Statement::PixelFilter, "mitchell", &[WIDTH_2, MITCHELL]),
    plugin_of(
        Statement::PixelFilter,
        "sinc",
        &[WIDTH_4, &[param("tau", Float(3.0), Rendered)]],
    ),
    plugin_of(Statement::PixelFilter, "triangle", &[WIDTH_2]),
    plugin_of(Statement::PixelFilter, "blackmanharris", &[WIDTH_4]),
    plugin_of(Statement::PixelFilter, "catmullrom", &[CATMULLROM_WIDTHS]),
    plugin_of(Statement::Material, "mirror", &[MIRROR_UNREAD]),
    plugin_of(Statement::Material, "plastic", &[ROUGHNESS_UNREAD]),
    plugin_of(Statement::Material, "shinymetal", &[ROUGHNESS_UNREAD]),
    plugin_of(Statement::Material, "roughglass", &[FILM_UNREAD]),
    plugin_of(Statement::Material, "glass2", &[FILM_UNREAD, GLASS2_UNREAD]),
    plugin_of(Statement::Material, "glossy", &[GLOSSY]),
    plugin_of(
        Statement::AreaLightSource,
        "area",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES, LIGHT_PROFILE],
    ),
    plugin_of(
        Statement::LightSource,
        "point",
        &[LIGHT_IMPORTANCE, LIGHT_PROFILE],
    ),
    // LuxRender's point light under its older name.
    plugin_of(
        Statement::LightSource,
        "goniometric",
        &[LIGHT_IMPORTANCE, LIGHT_PROFILE],
    ),
    plugin_of(Statement::LightSource, "spot", &[LIGHT_IMPORTANCE]),
    plugin_of(Statement::LightSource, "projection", &[LIGHT_IMPORTANCE]),
    plugin_of(
        Statement::LightSource,
        "distant",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES],
    ),
    plugin_of(
        Statement::LightSource,
        "infinite",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES],
    ),
    plugin_of(
        Statement::LightSource,
        "infinitesample",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES],
    ),
    plugin_of(
        Statement::LightSource,
        "sky",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES],
    ),
    plugin_of(
        Statement::LightSource,
        "sky2",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES],
    ),
    plugin_of(
        Statement::LightSource,
        "sun",
        &[LIGHT_IMPORTANCE, LIGHT_NSAMPLES],
    ),
    plugin_of(Statement::Texture, "imagemap", &[IMAGEMAP]),
    plugin_of(Statement::Shape, "mesh", &[MESH_TANGENTS]),
    plugin_of(Statement::Shape, "trianglemesh", &[MESH_TANGENTS]),
    plugin_of(Statement::Shape, "waldtrianglemesh", &[MESH_TANGENTS]),
    plugin_of(Statement::Shape, "barytrianglemesh", &[MESH_TANGENTS]),
    plugin_of(Statement::Shape, "loopsubdiv", &[MESH_TANGENTS]),
    plugin_of(Statement::Shape, "plymesh", &[MESH_TANGENTS]),
];

#[cfg(test)]
mod tests {
    use std::collections::HashSet;
    use std::sync::Arc;

    use super::*;
    use crate::assets::MemorySource;
    use crate::diag::Warning;
    use crate::parse::parse_scene;

    /// A parameter as a file writes it, given a value of its default's kind.
    fn written(name: &str, value: &LuxDefault) -> Option<String> {
        Some(match value {
            Bool(b) => format!("\"bool {name}\" [\"{b}\"]"),
            Int(i) => format!("\"integer {name}\" [{i}]"),
            Float(f) => format!("\"float {name}\" [{f}]"),
            Floats(fs) => {
                let fs: Vec<String> = fs.iter().map(f32::to_string).collect();
                format!("\"float {name}\" [{}]", fs.join(" "))
            }
            Text(t) => format!("\"string {name}\" [\"{t}\"]"),
            Derived(_, sample) => return written(name, sample),
            Unset => return None,
        })
    }

    /// Another value than `value`, of its kind.
    fn other_than(value: &LuxDefault) -> LuxDefault {
        match value {
            Bool(b) => Bool(!b),
            Int(i) => Int(i + 1),
            Float(f) => Float(f + 1.0),
            Floats(_) => Floats(&[0.5, 0.5, 0.5, 0.5]),
            Text(_) => Text("another"),
            Derived(_, sample) => other_than(sample),
            Unset => Text("another"),
        }
    }

    /// A scene whose one statement of interest is `plugin`'s with `params` (as written), and
    /// whatever that statement needs; None for the statements the builder skips whole.
    fn scene(plugin: &Plugin, params: &str) -> Option<String> {
        let name = plugin.name;
        let keyword = plugin.statement.keyword();
        let world = |statement: String| format!("WorldBegin\n{statement}\nWorldEnd\n");
        Some(match plugin.statement {
            Statement::Film
            | Statement::Sampler
            | Statement::SurfaceIntegrator
            | Statement::PixelFilter => {
                format!(
                    "{keyword} \"{name}\" {params}\nCamera \"perspective\"\n{}",
                    world(String::new())
                )
            }
            Statement::Camera => format!("Camera \"{name}\" {params}\n{}", world(String::new())),
            Statement::Material | Statement::LightSource => {
                world(format!("{keyword} \"{name}\" {params}"))
            }
            Statement::AreaLightSource => world(format!(
                "AreaLightSource \"{name}\" {params}\nShape \"sphere\""
            )),
            Statement::Texture => world(format!(
                "Texture \"t\" \"color\" \"{name}\" \"string filename\" [\"t.png\"] {params}"
            )),
            Statement::Shape if name == "plymesh" => world(format!(
                "Shape \"plymesh\" \"string filename\" [\"t.ply\"] {params}"
            )),
            Statement::Shape => world(format!(
                "Shape \"{name}\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0] \
                 {params}"
            )),
            Statement::VolumeIntegrator | Statement::Accelerator | Statement::Renderer => {
                return None
            }
        })
    }

    fn warnings(text: &str) -> Vec<Warning> {
        let mut source = MemorySource::new();
        source.insert("main.lxs", Arc::from(text.as_bytes()));
        let mut png = Vec::new();
        image::RgbImage::new(2, 2)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("a PNG encodes");
        source.insert("t.png", Arc::from(png));
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                   property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                   end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        source.insert("t.ply", Arc::from(ply.as_bytes()));
        parse_scene("main.lxs", &source)
            .unwrap_or_else(|e| panic!("{text}: {e}"))
            .warnings
    }

    /// The warnings about parameter `name` (messages quote it as `"type name"`).
    fn about<'w>(warnings: &'w [Warning], name: &str) -> Vec<&'w Warning> {
        let quoted = format!(" {name}\"");
        warnings
            .iter()
            .filter(|w| w.message.contains(&quoted))
            .collect()
    }

    /// Runs `test` on every (plugin, parameter) of the table whose statement the builder reads.
    fn each_read(mut test: impl FnMut(&Plugin, &LuxParam)) {
        for plugin in PLUGINS {
            if scene(plugin, "").is_some() {
                plugin.params().for_each(|param| test(plugin, param));
            }
        }
    }

    #[test]
    fn rendered_parameters_are_read_by_yat_without_a_word() {
        let mut checked = 0;
        each_read(|plugin, param| {
            if param.handling != Rendered {
                return;
            }
            let given = written(param.name, &param.default).expect("a rendered default");
            let text = scene(plugin, &given).expect("a statement the builder reads");
            let w = warnings(&text);
            assert!(about(&w, param.name).is_empty(), "{text}{w:#?}");
            assert!(
                w.iter().all(|w| w.severity != Severity::Differs),
                "LuxRender's default renders as LuxRender's: {text}{w:#?}"
            );
            checked += 1;
        });
        assert!(checked >= 60, "only {checked} rendered parameters checked");
    }

    #[test]
    fn no_effect_parameters_are_listed_with_their_reason() {
        let mut checked = 0;
        each_read(|plugin, param| {
            let Handling::NoEffect(why) = param.handling else {
                return;
            };
            let given = written(param.name, &param.default).expect("a default");
            let text = scene(plugin, &given).expect("a statement the builder reads");
            let w = warnings(&text);
            let found = about(&w, param.name);
            assert!(
                found.iter().any(|w| w.severity == Severity::NoEffect
                    && w.message.contains("no effect on the image")
                    && w.message.contains(why.reason())),
                "{text}{w:#?}"
            );
            assert!(
                found.iter().all(|w| w.severity == Severity::NoEffect),
                "{text}{w:#?}"
            );
            checked += 1;
        });
        assert!(checked >= 50, "only {checked} no-effect parameters checked");
    }

    /// Parameters YAT ignores that change LuxRender's image: a difference, except at LuxRender's
    /// default (a note: the same image) or without what enables them (no effect).
    #[test]
    fn differing_parameters_differ_only_where_they_change_luxrenders_image() {
        let mut checked = 0;
        each_read(|plugin, param| {
            let Handling::Differs { unless, .. } = param.handling else {
                return;
            };
            let severity_of = |given: &str| {
                let text = scene(plugin, given).expect("a statement the builder reads");
                let w = warnings(&text);
                let found = about(&w, param.name);
                assert_eq!(found.len(), 1, "{text}{w:#?}");
                found[0].severity
            };
            let other = written(param.name, &other_than(&param.default)).expect("a value");
            match unless {
                Unless::Never => assert_eq!(severity_of(&other), Severity::Differs),
                Unless::Default => {
                    let default = written(param.name, &param.default).expect("a default");
                    assert_eq!(severity_of(&default), Severity::Note, "{default}");
                    assert_eq!(severity_of(&other), Severity::Differs, "{other}");
                }
                Unless::Untriggered(triggers) => {
                    assert_eq!(severity_of(&other), Severity::NoEffect, "{other}");
                    for trigger in triggers {
                        let enabler = match *trigger {
                            Trigger::Is(name, value) => match plugin.param(name) {
                                Some(LuxParam {
                                    default: Bool(_), ..
                                }) => format!("\"bool {name}\" [\"{value}\"]"),
                                _ => format!("\"string {name}\" [\"{value}\"]"),
                            },
                            Trigger::Given(name) => format!("\"string {name}\" [\"t.png\"]"),
                        };
                        let given = format!("{enabler} {other}");
                        assert_eq!(severity_of(&given), Severity::Differs, "{given}");
                    }
                }
            }
            checked += 1;
        });
        assert!(checked >= 30, "only {checked} differing parameters checked");
    }

    #[test]
    fn parameters_luxrender_never_reads_are_notes() {
        let multiimage = plugin("Film \"multiimage\"").expect("listed");
        let w = warnings(&scene(multiimage, "\"string tonemapper\" [\"linear\"]").unwrap());
        let found = about(&w, "tonemapper");
        assert_eq!(found.len(), 1, "{w:#?}");
        assert_eq!(found[0].severity, Severity::Note);
        assert!(
            found[0].message.starts_with(
                "Film \"multiimage\": \"string tonemapper\" is ignored, as LuxRender ignores it \
                 (LuxRender 1.x reads multiimage as fleximage, whose is tonemapkernel)"
            ),
            "{w:#?}"
        );
        // Outside the table and unread: perhaps one LuxRender reads.
        let fleximage = plugin("Film \"fleximage\"").expect("listed");
        let w = warnings(&scene(fleximage, "\"float wobble\" [1]").unwrap());
        assert_eq!(
            w.iter()
                .map(|w| (w.severity, w.message.as_str()))
                .collect::<Vec<_>>(),
            [(
                Severity::Differs,
                "Film \"fleximage\": unknown parameter \"float wobble\" ignored"
            )]
        );
    }

    #[test]
    fn no_plugin_or_parameter_is_listed_twice() {
        let mut plugins = HashSet::new();
        for plugin in PLUGINS {
            assert!(
                plugins.insert((plugin.statement, plugin.name)),
                "{:?} \"{}\" twice",
                plugin.statement,
                plugin.name
            );
            let mut names = HashSet::new();
            for param in plugin.params() {
                assert!(
                    names.insert(param.name),
                    "{:?} \"{}\": \"{}\" twice",
                    plugin.statement,
                    plugin.name,
                    param.name
                );
            }
        }
    }

    /// Every name LuxRender 1.x registers a plugin of these statements under.
    #[test]
    fn every_luxrender_plugin_is_listed() {
        use Statement::*;
        let registered: &[(Statement, &[&str])] = &[
            (Film, &["fleximage", "multiimage"]),
            (
                Sampler,
                &["random", "lowdiscrepancy", "metropolis", "erpt", "sobol"],
            ),
            (
                SurfaceIntegrator,
                &[
                    "path",
                    "bidirectional",
                    "directlighting",
                    "distributedpath",
                    "exphotonmap",
                    "igi",
                    "sppm",
                ],
            ),
            (VolumeIntegrator, &["emission", "single", "multi", "none"]),
            (
                Camera,
                &["perspective", "orthographic", "environment", "realistic"],
            ),
            (
                Accelerator,
                &[
                    "bvh",
                    "qbvh",
                    "sqbvh",
                    "kdtree",
                    "tabreckdtree",
                    "unsafekdtree",
                    "bruteforce",
                    "none",
                ],
            ),
            (
                Renderer,
                &[
                    "sampler",
                    "hybrid",
                    "hybridsampler",
                    "sppm",
                    "luxcore",
                    "slg",
                ],
            ),
            (
                PixelFilter,
                &[
                    "box",
                    "gaussian",
                    "mitchell",
                    "sinc",
                    "triangle",
                    "blackmanharris",
                    "catmullrom",
                ],
            ),
        ];
        for (statement, names) in registered {
            for name in *names {
                let label = format!("{} \"{name}\"", statement.keyword());
                let found = plugin(&label).unwrap_or_else(|| panic!("{label} is not listed"));
                assert_eq!((found.statement, found.name), (*statement, *name));
            }
        }
        assert!(plugin("Film \"fleximage").is_none());
        assert!(plugin("Shape \"sphere\"").is_none());
    }

    #[test]
    fn values_are_shown_as_a_person_reads_them() {
        assert_eq!(shown(&Values::Numbers(vec![0.400000005960464])), "[0.4]");
        assert_eq!(shown(&Values::Numbers(vec![1e30, 0.0, 2.0])), "[1e30 0 2]");
        assert_eq!(shown(&Values::Strings(vec!["cut".into()])), "[\"cut\"]");
        assert_eq!(
            shown(&Values::Numbers(vec![1.0, 2.0, 3.0, 4.0, 5.0])),
            "[1 2 3 4 ...]"
        );
    }
}
