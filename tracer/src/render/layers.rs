//! The layers a render's units may carry besides radiance and weight: per pixel, sums of a value
//! each camera sample gives, whose weighted mean through the pixel filter is the pixel's value,
//! as the colour's is, and the count of samples taken in the pixel.
//!
//! - Alpha: LuxRender's coverage of the camera ray (0 where it escapes to the environment
//!   having met nothing but surfaces it crosses straight on, null surfaces and architectural
//!   panes; 1 where it meets anything else): kept when a file the Film writes has an alpha
//!   channel.
//! - The AOVs `yat render --aovs` asks for (and the scene's `write_exr_ZBuf`, depth), written
//!   as extra channels of the EXR, from the camera ray's first surface that is not `null`:
//!   albedo (its BSDF's reflectance, a coating left out; 0 where the ray escapes), shading
//!   normal (world space, on the camera's side; 0 where it escapes), depth (the distance from
//!   the camera ray's origin, a mean over the samples that hit: two sums, the weighted distance
//!   and the weight), samples (the camera samples taken in the pixel, unfiltered).
//!
//! - Light groups (a scene with two or more `LightGroup`s, `film::light_groups`): each group's
//!   light, three sums a group, as the colour's.
//!
//! Which layers a render keeps is part of its film frame, which every node derives from the
//! scene and the settings alike, so a render that keeps none has the buffers, wire bytes and
//! checkpoint it always had. A leaf.

use glam::Vec3;

use crate::film::light_groups::MAX_LIGHT_GROUPS;

/// The AOVs a render is asked for (`--aovs`; depth also by the Film's `write_exr_ZBuf`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Aovs {
    pub albedo: bool,
    pub normal: bool,
    pub depth: bool,
    pub samples: bool,
}

impl Aovs {
    pub const NONE: Self = Self {
        albedo: false,
        normal: false,
        depth: false,
        samples: false,
    };

    /// The names `--aovs` takes, in the order of their bits on the wire.
    pub const NAMES: [&'static str; 4] = ["albedo", "normal", "depth", "samples"];

    /// The AOVs of a comma-separated list of [`Self::NAMES`]; Err names the unknown one.
    pub fn from_names(list: &str) -> Result<Self, String> {
        let mut aovs = Self::NONE;
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            match name {
                "albedo" => aovs.albedo = true,
                "normal" => aovs.normal = true,
                "depth" => aovs.depth = true,
                "samples" => aovs.samples = true,
                other => {
                    return Err(format!(
                        "unknown AOV \"{other}\" (known: {})",
                        Self::NAMES.join(", ")
                    ))
                }
            }
        }
        Ok(aovs)
    }

    /// As the wire carries them: bit i for [`Self::NAMES`]`[i]`.
    pub fn bits(self) -> u32 {
        [self.albedo, self.normal, self.depth, self.samples]
            .iter()
            .enumerate()
            .map(|(i, &on)| u32::from(on) << i)
            .sum()
    }

    /// From [`Self::bits`]; None with a bit no AOV has.
    pub fn from_bits(bits: u32) -> Option<Self> {
        (bits >> Self::NAMES.len() == 0).then_some(Self {
            albedo: bits & 1 != 0,
            normal: bits & 2 != 0,
            depth: bits & 4 != 0,
            samples: bits & 8 != 0,
        })
    }

    pub fn is_empty(self) -> bool {
        self == Self::NONE
    }

    /// The AOVs of either.
    pub fn or(self, other: Self) -> Self {
        Self {
            albedo: self.albedo || other.albedo,
            normal: self.normal || other.normal,
            depth: self.depth || other.depth,
            samples: self.samples || other.samples,
        }
    }

    /// Whether a sample needs its camera ray's first surface (albedo, normal or depth).
    pub fn need_first_surface(self) -> bool {
        self.albedo || self.normal || self.depth
    }
}

/// Which layers a render's units carry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Layers {
    pub alpha: bool,
    pub aovs: Aovs,
    /// The light groups whose light is kept apart: 0, or 2 ..= [`MAX_LIGHT_GROUPS`].
    pub light_groups: u8,
}

/// Where each layer's sums sit among a pixel's [`Layers::len`] sums.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LayerOffsets {
    /// Weight x alpha.
    pub alpha: Option<usize>,
    /// Weight x albedo, three sums.
    pub albedo: Option<usize>,
    /// Weight x normal, three sums.
    pub normal: Option<usize>,
    /// Weight x distance over the samples that hit, then their weight: two sums.
    pub depth: Option<usize>,
    /// The samples taken in the pixel (not filtered): one sum.
    pub samples: Option<usize>,
    /// Weight x each light group's light, three sums a group.
    pub light_groups: Option<usize>,
}

impl Layers {
    /// No layer: radiance and weight alone.
    pub const NONE: Self = Self {
        alpha: false,
        aovs: Aovs::NONE,
        light_groups: 0,
    };

    /// The f32 sums per pixel a unit's buffer holds for them (i64 in the film), laid out as
    /// [`Self::offsets`] says.
    pub fn len(self) -> usize {
        let o = self.offsets();
        [
            (o.alpha, 1),
            (o.albedo, 3),
            (o.normal, 3),
            (o.depth, 2),
            (o.samples, 1),
            (o.light_groups, 3 * usize::from(self.light_groups)),
        ]
        .iter()
        .map(|&(at, n)| if at.is_some() { n } else { 0 })
        .sum()
    }

    pub fn is_empty(self) -> bool {
        self.len() == 0
    }

    /// Where each layer's sums are: alpha, albedo, normal, depth, samples, light groups, in
    /// that order, those the render keeps.
    pub fn offsets(self) -> LayerOffsets {
        let mut at = 0;
        let mut next = |on: bool, n: usize| {
            on.then(|| {
                at += n;
                at - n
            })
        };
        LayerOffsets {
            alpha: next(self.alpha, 1),
            albedo: next(self.aovs.albedo, 3),
            normal: next(self.aovs.normal, 3),
            depth: next(self.aovs.depth, 2),
            samples: next(self.aovs.samples, 1),
            light_groups: next(self.light_groups > 0, 3 * usize::from(self.light_groups)),
        }
    }

    /// Whether sum `k` of a pixel is a filtered value in [-1, 1] times the weight (alpha,
    /// albedo, normal, depth's weight), a sum of any size (the distance, a light group's
    /// light: finite, bounded only as the film's sums are), or the sample count.
    pub fn kind(self, k: usize) -> SumKind {
        let o = self.offsets();
        if o.samples == Some(k) {
            SumKind::Count
        } else if o.depth == Some(k) || o.light_groups.is_some_and(|at| k >= at) {
            SumKind::Unbounded
        } else {
            SumKind::Weighted
        }
    }
}

/// What a layer sum holds, for the checks a peer's sums must pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SumKind {
    /// A value in [-1, 1] per sample times its filter weight: bounded as the weight sum is.
    Weighted,
    /// A distance times the weight: finite, bounded only as the film's sums are.
    Unbounded,
    /// The samples taken in the pixel: exactly what the unit renders there.
    Count,
}

/// The most sums per pixel any set of layers has.
pub const MAX_LAYER_SUMS: usize = 10 + 3 * MAX_LIGHT_GROUPS;

/// What one camera sample gives the filtered layers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerSample {
    /// 1 where the camera ray met something, 0 where it escaped.
    pub alpha: f32,
    /// The first surface's albedo, each channel in [0, 1]; 0 without one.
    pub albedo: Vec3,
    /// The first surface's shading normal on the camera's side; 0 without one.
    pub normal: Vec3,
    /// The first surface's distance from the camera ray's origin; None without one.
    pub depth: Option<f32>,
    /// Each light group's light (the first [`Layers::light_groups`] kept).
    pub light_groups: [Vec3; MAX_LIGHT_GROUPS],
}

impl LayerSample {
    /// A sample with only its alpha.
    pub fn alpha(alpha: f32) -> Self {
        Self {
            alpha,
            albedo: Vec3::ZERO,
            normal: Vec3::ZERO,
            depth: None,
            light_groups: [Vec3::ZERO; MAX_LIGHT_GROUPS],
        }
    }

    /// The sample's values of `layers` to be weighed by the filter, at their offsets (the
    /// sample count's left 0: it is added to the sample's own pixel alone).
    pub fn values(&self, layers: Layers) -> [f32; MAX_LAYER_SUMS] {
        let mut out = [0.0; MAX_LAYER_SUMS];
        let o = layers.offsets();
        if let Some(at) = o.alpha {
            out[at] = self.alpha;
        }
        if let Some(at) = o.albedo {
            out[at..at + 3].copy_from_slice(&self.albedo.to_array());
        }
        if let Some(at) = o.normal {
            out[at..at + 3].copy_from_slice(&self.normal.to_array());
        }
        if let (Some(at), Some(d)) = (o.depth, self.depth) {
            out[at] = d;
            out[at + 1] = 1.0;
        }
        if let Some(at) = o.light_groups {
            let groups = &self.light_groups[..usize::from(layers.light_groups)];
            for (sums, light) in out[at..].chunks_exact_mut(3).zip(groups) {
                sums.copy_from_slice(&light.to_array());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_lay_out_their_sums_in_order() {
        let all = Layers {
            alpha: true,
            aovs: Aovs::from_names("albedo,normal, depth,samples").unwrap(),
            light_groups: MAX_LIGHT_GROUPS as u8,
        };
        assert_eq!(all.len(), MAX_LAYER_SUMS);
        let o = all.offsets();
        assert_eq!(
            (
                o.alpha,
                o.albedo,
                o.normal,
                o.depth,
                o.samples,
                o.light_groups
            ),
            (Some(0), Some(1), Some(4), Some(7), Some(9), Some(10))
        );
        assert_eq!(
            (all.kind(0), all.kind(7), all.kind(8), all.kind(9)),
            (
                SumKind::Weighted,
                SumKind::Unbounded,
                SumKind::Weighted,
                SumKind::Count
            )
        );
        // A light group's light is a sum of any size, as the colour's.
        assert!((10..MAX_LAYER_SUMS).all(|k| all.kind(k) == SumKind::Unbounded));
        let depth = Layers {
            alpha: false,
            aovs: Aovs::from_names("depth").unwrap(),
            light_groups: 0,
        };
        assert_eq!((depth.len(), depth.offsets().depth), (2, Some(0)));
        assert_eq!(Layers::NONE.len(), 0);
        assert!(Aovs::from_names("albedo,zdepth")
            .unwrap_err()
            .contains("\"zdepth\""));
        for bits in 0..16 {
            assert_eq!(Aovs::from_bits(bits).unwrap().bits(), bits);
        }
        assert!(Aovs::from_bits(16).is_none());
    }
}
