//! `SurfaceIntegrator "path" ...`: the integrator's settings, LuxRender's defaults and their
//! reading. "bidirectional" renders as path tracing with its eye depth unless the command line
//! chooses it; "directlighting" renders as LuxRender's direct lighting; others as path tracing.
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `maxdepth` (path) | integer | 16 |
//! | `maxdepth` (directlighting) | integer | 5: specular bounces after the camera's first hit |
//! | `eyedepth`, `lightdepth` (bidirectional) | integer | 8 (LuxRender 1.x's) |
//! | `eyerrthreshold`, `lightrrthreshold` (bidirectional) | float | 0: the least survival probability of each subpath's roulette |
//! | `rrstrategy` | string: efficiency, probability, none | efficiency |
//! | `rrcontinueprob` | float | 0.65 |
//! | `includeenvironment` | bool | true |
//! | `mirrorimages` (YAT's own) | bool | true: lamps are also sampled through flat mirrors ([`crate::lights::ImageSample`]) |
//! | `glossysplit` (YAT's own) | bool | true: a path's first glossy vertex that may see a lamp takes several BSDF samples for the lamps it sees directly ([`crate::integrator::GLOSSY_SPLIT`]) |
//!
//! Without a `SurfaceIntegrator` statement the scene renders with `"path"` and these defaults.

use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// Bounces per path when the file does not say.
pub const DEFAULT_MAX_DEPTH: i32 = 16;
/// Specular bounces of a direct-lighting path when the file does not say (LuxRender 1.x's).
pub const DEFAULT_DIRECT_DEPTH: i32 = 5;
/// Scattering vertices of each bidirectional subpath when the file does not say.
pub const DEFAULT_SUBPATH_DEPTH: i32 = 8;
/// Survival probability of `rrstrategy "probability"` when the file does not say.
pub const DEFAULT_RR_CONTINUE_PROB: f32 = 0.65;
/// Whether camera rays that escape see the environment.
pub const DEFAULT_INCLUDE_ENVIRONMENT: bool = true;
/// Whether lamps are sampled through flat mirrors too (the same image, less noise where a
/// mirror throws light; false renders plain path tracing's estimate, for comparisons).
pub const DEFAULT_MIRROR_IMAGES: bool = true;
/// Whether a path's first glossy vertex that may see a lamp takes several BSDF samples for the
/// light it sees directly (the same image, less noise in highlights; false takes one, for
/// comparisons).
pub const DEFAULT_GLOSSY_SPLIT: bool = true;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RussianRoulette {
    Efficiency,
    Probability,
    None,
}

#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorDesc {
    pub max_depth: u32,
    pub rr_strategy: RussianRoulette,
    pub rr_continue_prob: f32,
    pub include_environment: bool,
    /// Lamps are sampled through flat mirrors as well as directly.
    pub mirror_images: bool,
    /// A path's first glossy vertex that may see a lamp splits (see
    /// [`crate::integrator::GLOSSY_SPLIT`]).
    pub glossy_split: bool,
    /// The SurfaceIntegrator the file named (e.g. "bidirectional" rendered as path).
    pub requested: String,
    /// Scattering vertices of a bidirectional light subpath at most (`lightdepth`).
    pub light_depth: u32,
    /// The least survival probabilities of a bidirectional camera and light subpath's
    /// roulette (`eyerrthreshold`, `lightrrthreshold`).
    pub eye_rr_threshold: f32,
    pub light_rr_threshold: f32,
}

/// The light transport an image is rendered with: the scene's SurfaceIntegrator or the
/// command line's choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Transport {
    /// Path tracing with next-event estimation ([`crate::integrator::trace_path`]).
    #[default]
    Path,
    /// Bidirectional path tracing ([`crate::integrator::bdpt`]).
    Bidirectional,
    /// LuxRender's direct lighting: the path tracer's walk through specular vertices only, to
    /// the first non-specular vertex, which takes the direct light (a light sample and a BSDF
    /// sample weighed by MIS) and ends the path ([`crate::integrator::PathScene::direct_lighting`]).
    DirectLighting,
}

impl Transport {
    pub fn name(self) -> &'static str {
        match self {
            Transport::Path => "path",
            Transport::Bidirectional => "bidirectional",
            Transport::DirectLighting => "directlighting",
        }
    }

    /// The transport named `name` (as the command line and the wire write it).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "path" => Some(Transport::Path),
            "bidirectional" => Some(Transport::Bidirectional),
            "directlighting" => Some(Transport::DirectLighting),
            _ => None,
        }
    }
}

impl IntegratorDesc {
    /// The transport the scene asks for when the command line does not choose: direct
    /// lighting for "directlighting"; for "bidirectional", bidirectional path tracing where the
    /// scene has caustics of delta lights (`delta_caustics`, [`crate::desc::SceneDesc::delta_caustics`]),
    /// which path tracing cannot carry, and path tracing elsewhere, the same image sooner (see
    /// docs/architecture.md, "Integrators"); path tracing otherwise.
    pub fn transport(&self, delta_caustics: bool) -> Transport {
        match self.requested.as_str() {
            "directlighting" => Transport::DirectLighting,
            "bidirectional" if delta_caustics => Transport::Bidirectional,
            _ => Transport::Path,
        }
    }

    /// The path integrator with every default, recorded as `requested`.
    pub fn path_defaults(requested: &str) -> Self {
        Self {
            max_depth: DEFAULT_MAX_DEPTH as u32,
            rr_strategy: RussianRoulette::Efficiency,
            rr_continue_prob: DEFAULT_RR_CONTINUE_PROB,
            include_environment: DEFAULT_INCLUDE_ENVIRONMENT,
            mirror_images: DEFAULT_MIRROR_IMAGES,
            glossy_split: DEFAULT_GLOSSY_SPLIT,
            requested: requested.to_string(),
            light_depth: DEFAULT_SUBPATH_DEPTH as u32,
            eye_rr_threshold: 0.0,
            light_rr_threshold: 0.0,
        }
    }

    /// Reads `SurfaceIntegrator "ty"`.
    pub fn read(
        ctx: &mut dyn ParseContext,
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
    ) -> Result<Self, ParseError> {
        let depth = |name: &str, default: i32| -> Result<u32, ParseError> {
            let d = params.int(name, default)?;
            match params.find(name) {
                Some(p) if d < 0 => Err(params.error(p, "the depth cannot be negative")),
                _ => Ok(d as u32),
            }
        };
        match ty {
            "path" => {
                let strategy = params.string_or("rrstrategy", "efficiency")?;
                let rr_strategy = match strategy.as_str() {
                    "efficiency" => RussianRoulette::Efficiency,
                    "probability" => RussianRoulette::Probability,
                    "none" => RussianRoulette::None,
                    other => {
                        ctx.warn(pos, format!("SurfaceIntegrator \"path\": unknown rrstrategy \"{other}\"; using efficiency"));
                        RussianRoulette::Efficiency
                    }
                };
                params.ignore("lightstrategy");
                params.ignore("shadowraycount");
                Ok(IntegratorDesc {
                    max_depth: depth("maxdepth", DEFAULT_MAX_DEPTH)?,
                    rr_strategy,
                    rr_continue_prob: params.float("rrcontinueprob", DEFAULT_RR_CONTINUE_PROB)?,
                    include_environment: params
                        .bool("includeenvironment", DEFAULT_INCLUDE_ENVIRONMENT)?,
                    mirror_images: params.bool("mirrorimages", DEFAULT_MIRROR_IMAGES)?,
                    glossy_split: params.bool("glossysplit", DEFAULT_GLOSSY_SPLIT)?,
                    ..Self::path_defaults(ty)
                })
            }
            "bidirectional" => {
                let max_depth = depth("eyedepth", DEFAULT_SUBPATH_DEPTH)?;
                let light_depth = depth("lightdepth", DEFAULT_SUBPATH_DEPTH)?;
                let threshold = |name: &str| -> Result<f32, ParseError> {
                    let v = params.float(name, 0.0)?;
                    match params.find(name) {
                        Some(p) if !(0.0..=1.0).contains(&v) => {
                            Err(params.error(p, "a survival probability lies in [0, 1]"))
                        }
                        _ => Ok(v),
                    }
                };
                let (eye_rr_threshold, light_rr_threshold) =
                    (threshold("eyerrthreshold")?, threshold("lightrrthreshold")?);
                for name in ["lightraycount", "lightpathstrategy", "lightstrategy"] {
                    params.ignore(name);
                }
                ctx.note_once(
                    "bidirectional".into(),
                    pos,
                    format!("SurfaceIntegrator \"bidirectional\" is rendered bidirectional where the scene has caustics of point, spot or distant lights (a mirror, smooth glass or metal under one: path tracing cannot carry them), else as path tracing with max depth {max_depth} (its eyedepth), the same image sooner; --integrator chooses (yat check's integrator line says which runs)"),
                );
                Ok(IntegratorDesc {
                    max_depth,
                    light_depth,
                    eye_rr_threshold,
                    light_rr_threshold,
                    ..Self::path_defaults(ty)
                })
            }
            "directlighting" => {
                // LuxRender counts the specular bounces after the first hit; the walk counts
                // the vertices that take the light: one more.
                let specular = depth("maxdepth", DEFAULT_DIRECT_DEPTH)?;
                for name in ["lightstrategy", "shadowraycount"] {
                    params.ignore(name);
                }
                Ok(IntegratorDesc {
                    max_depth: specular.saturating_add(1),
                    // LuxRender's direct lighting plays no roulette on its specular chains.
                    rr_strategy: RussianRoulette::None,
                    ..Self::path_defaults(ty)
                })
            }
            other => {
                params.ignore_all();
                ctx.warn(pos, format!("SurfaceIntegrator \"{other}\" is not available; rendering with \"path\" and its defaults"));
                Ok(Self::path_defaults(other))
            }
        }
    }
}
