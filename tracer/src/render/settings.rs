//! Everything besides the scene that decides the image: the resolved render settings and the
//! command-line overrides they are resolved from.

use crate::desc::{LatLongConvention, SceneDesc};
use crate::integrator::options::Transport;
use crate::render::layers::{Aovs, Layers};
use crate::render::unit::FilmFrame;

/// Everything besides the scene that decides the image. Identical settings and scene give
/// bit-identical images whatever renders them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    pub latlong: LatLongConvention,
    pub transport: Transport,
    /// The AOVs asked for (`--aovs`), written as the EXR's extra channels.
    pub aovs: Aovs,
}

#[cfg(test)]
impl RenderSettings {
    /// Settings of a `width` x `height` image at `spp` (depth 4, seed 0) for the render
    /// modules' unit tests.
    pub(crate) fn for_tests(width: u32, height: u32, spp: u32) -> Self {
        Self {
            width,
            height,
            spp,
            max_depth: 4,
            seed: 0,
            latlong: LatLongConvention::Seed,
            transport: Transport::Path,
            aovs: Aovs::NONE,
        }
    }
}

/// Command-line overrides of what the scene file says.
#[derive(Clone, Debug, Default)]
pub struct RenderOverrides {
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    pub seed: Option<u64>,
    pub resolution: Option<(u32, u32)>,
    pub latlong: LatLongConvention,
    pub transport: Option<Transport>,
    /// The share of pixels still changing at which the render halts, in place of the scene's
    /// `haltthreshold`; a negative one lifts the scene's (LuxRender's "off").
    pub halt_threshold: Option<f32>,
    pub aovs: Aovs,
}

impl RenderOverrides {
    /// The share of pixels still changing at which the render halts: the command line's, else
    /// the scene's `haltthreshold`; None when neither sets one or the command line lifts it.
    pub fn halt_threshold(&self, desc: &SceneDesc) -> Option<f32> {
        match self.halt_threshold {
            Some(t) if t < 0.0 => None,
            Some(t) => Some(t),
            None => desc.film.haltthreshold,
        }
    }
}

/// Samples per pixel when neither the file nor the command line says.
pub const DEFAULT_SPP: u32 = 64;

/// Widest or tallest image, in pixels.
pub const MAX_SIDE: u32 = 65_536;
/// Largest image, in pixels (a 16k x 16k render): its film is 8 GiB of sums.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 28;
/// Most samples per pixel: 16.7 million, far beyond any converged image, small enough that
/// every count a plan derives from it (samples of a unit, of the image) fits its integer.
pub const MAX_SPP: u32 = 1 << 24;
/// Deepest path: LuxRender's default is 10, scenes use up to a few hundred.
pub const MAX_DEPTH: u32 = 1 << 12;

/// Settings outside what a render can be planned for.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum SettingsError {
    #[error("the image size {width}x{height} must be positive")]
    EmptyImage { width: u32, height: u32 },
    #[error("the image size {width}x{height} exceeds the limit of {MAX_SIDE} pixels a side and {MAX_IMAGE_PIXELS} pixels in all")]
    ImageTooLarge { width: u32, height: u32 },
    #[error("{0} samples per pixel: at least 1 and at most {MAX_SPP}")]
    Spp(u32),
    #[error("path depth {0} exceeds the limit of {MAX_DEPTH}")]
    Depth(u32),
}

impl RenderSettings {
    /// Checks the settings against the limits above, which every node enforces alike.
    pub fn check(&self) -> Result<(), SettingsError> {
        let (width, height) = (self.width, self.height);
        if width == 0 || height == 0 {
            return Err(SettingsError::EmptyImage { width, height });
        }
        if width > MAX_SIDE
            || height > MAX_SIDE
            || u64::from(width) * u64::from(height) > MAX_IMAGE_PIXELS
        {
            return Err(SettingsError::ImageTooLarge { width, height });
        }
        if self.spp == 0 || self.spp > MAX_SPP {
            return Err(SettingsError::Spp(self.spp));
        }
        if self.max_depth > MAX_DEPTH {
            return Err(SettingsError::Depth(self.max_depth));
        }
        Ok(())
    }

    /// The frame of this render's film: the image size, the border the scene's pixel filter
    /// gives every unit's buffer, whether units carry light splats (a bidirectional render's,
    /// [`Self::renders_bidirectional`]) and the layers they carry (alpha where a file the
    /// Film writes has an alpha channel, `FilmOutputs::needs_alpha`; the AOVs asked for, and
    /// depth where the Film's EXR has a Z channel). Every node makes its frame with this, so a
    /// peer's buffer is checked against the same frame everywhere.
    pub fn film_frame(&self, desc: &SceneDesc) -> FilmFrame {
        FilmFrame {
            width: self.width,
            height: self.height,
            border: desc.filter.border(),
            light_splats: self.renders_bidirectional(desc),
            layers: Layers {
                alpha: desc.film.outputs.needs_alpha(),
                aovs: self.aovs.or(Aovs {
                    depth: desc.film.outputs.exr_zbuf,
                    ..Aovs::NONE
                }),
                light_groups: self.light_group_layers(desc),
            },
        }
    }

    /// The light groups whose light the render keeps apart: every group of a scene with two or
    /// more (`film::light_groups`), none for one with fewer.
    pub fn light_group_layers(&self, desc: &SceneDesc) -> u8 {
        let groups = &desc.film.light_groups;
        if groups.layered() {
            groups.groups.len() as u8
        } else {
            0
        }
    }

    /// Whether `desc` renders with bidirectional path tracing under these settings: they
    /// choose it (any scene can, volumes included: both subpaths walk through them).
    pub fn renders_bidirectional(&self, _desc: &SceneDesc) -> bool {
        self.transport == Transport::Bidirectional
    }

    pub fn resolve(desc: &SceneDesc, overrides: &RenderOverrides) -> Self {
        let (width, height) = overrides
            .resolution
            .unwrap_or((desc.film.xresolution, desc.film.yresolution));
        // A render halted by convergence goes on until its image stops changing (LuxRender's
        // sampler has no total of its own): at most MAX_SPP unless the scene or the command
        // line sets a samples halt.
        let converging = overrides.halt_threshold(desc).map(|_| MAX_SPP);
        let spp = overrides
            .spp
            .or(desc.film.haltspp)
            .or(converging)
            .or(desc.sampler.pixel_samples)
            .unwrap_or(DEFAULT_SPP)
            .max(1);
        Self {
            width: width.max(1),
            height: height.max(1),
            spp,
            max_depth: overrides.max_depth.unwrap_or(desc.integrator.max_depth),
            seed: overrides.seed.unwrap_or(0),
            latlong: overrides.latlong,
            transport: overrides.transport.unwrap_or_else(|| desc.transport()),
            aovs: overrides.aovs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(width: u32, height: u32, spp: u32, max_depth: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            spp,
            max_depth,
            seed: 0,
            latlong: LatLongConvention::Seed,
            transport: Transport::Path,
            aovs: Default::default(),
        }
    }

    #[test]
    fn limits_are_inclusive_and_name_what_is_wrong() {
        assert_eq!(settings(MAX_SIDE, 4096, MAX_SPP, MAX_DEPTH).check(), Ok(()));
        assert_eq!(
            settings(0, 10, 1, 1).check(),
            Err(SettingsError::EmptyImage {
                width: 0,
                height: 10
            })
        );
        assert!(matches!(
            settings(MAX_SIDE + 1, 1, 1, 1).check(),
            Err(SettingsError::ImageTooLarge { .. })
        ));
        assert!(matches!(
            settings(MAX_SIDE, MAX_SIDE, 1, 1).check(),
            Err(SettingsError::ImageTooLarge { .. })
        ));
        assert_eq!(
            settings(8, 8, u32::MAX, 1).check(),
            Err(SettingsError::Spp(u32::MAX))
        );
        assert_eq!(settings(8, 8, 0, 1).check(), Err(SettingsError::Spp(0)));
        assert_eq!(
            settings(8, 8, 1, MAX_DEPTH + 1).check(),
            Err(SettingsError::Depth(MAX_DEPTH + 1))
        );
    }
}
