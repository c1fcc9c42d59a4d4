//! Light groups: `LightGroup "name"` puts the lights that follow it (to the end of the
//! attribute block) in a group; the film keeps each group's light apart as a layer (a render
//! of a scene with two or more groups) and makes the image from the groups, each weighed by
//! its settings, as LuxRender 1.x's film does with its buffer groups.
//!
//! A light declared outside every group is in "default", created where the first such light
//! is, as LuxRender's context does; groups are numbered in the order they first appear.
//!
//! A group's settings are LuxRender 1.x's (its film's `LG_ENABLE`, `LG_SCALE`,
//! `LG_SCALE_RED/GREEN/BLUE`, `LG_TEMPERATURE`), which LuxRender sets from its window and keeps
//! in its `.flm`; YAT reads them from the `LightGroup` statement's parameter list, which
//! LuxRender's parser reads and leaves (so a scene that gives them renders the plain sum of the
//! groups in LuxRender):
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `enabled` | bool | true: false leaves the group out of the image (its layer is kept) |
//! | `scale` | float | 1 |
//! | `rgbscale` | color | 1 1 1: the white the group's light is adapted to (LuxRender's adaptation tints white towards it, not exactly to it) |
//! | `temperature` | float, kelvin | 0 (off): the blackbody white it is adapted to |
//!
//! The weighing is LuxRender's `ComputeGroupScale`: in XYZ, the matrix that adapts the film's
//! white (sRGB 1 1 1) to `rgbscale`'s XYZ, times the one adapting it to the temperature's
//! blackbody (scaled to Y = 1), times `scale`; each is LuxRender's colour adaptation, the
//! ratio of the two whites' XYZ between the Bradford matrix and its inverse.
//!
//! Bounds: at most [`MAX_LIGHT_GROUPS`] groups (three sums per pixel each in a unit's buffer,
//! on the wire and in the film: with every other layer, the widest filter and an adaptive
//! unit's source planes, the largest reply stays under a worker's 8 MiB message limit); a
//! scene that names more is refused where it names the next.

use glam::{DMat3, DVec3, Vec3};

use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::{blackbody_xyz, linear_srgb_to_xyz, LINEAR_SRGB_TO_XYZ};

/// The most light groups a scene may have.
pub const MAX_LIGHT_GROUPS: usize = 6;

/// The name of the group of lights declared outside every `LightGroup`.
pub const DEFAULT_GROUP: &str = "default";

/// A light group and its settings.
#[derive(Clone, Debug, PartialEq)]
pub struct LightGroupDesc {
    pub name: String,
    pub enabled: bool,
    pub scale: f32,
    pub rgb_scale: Vec3,
    /// Kelvin; 0 (or less): no temperature.
    pub temperature: f32,
}

impl LightGroupDesc {
    /// A group with LuxRender's settings: enabled, scale 1, white, no temperature.
    pub fn named(name: &str) -> Self {
        Self {
            name: name.to_string(),
            enabled: true,
            scale: 1.0,
            rgb_scale: Vec3::ONE,
            temperature: 0.0,
        }
    }

    /// Reads the settings a `LightGroup` statement gives (those it leaves keep their values:
    /// a later statement naming the group again changes only what it gives).
    pub(crate) fn read_settings(&mut self, params: &ParamList) -> Result<(), ParseError> {
        self.enabled = params.bool("enabled", self.enabled)?;
        self.scale = params.float("scale", self.scale)?;
        self.rgb_scale = params.color("rgbscale", self.rgb_scale)?;
        self.temperature = params.float("temperature", self.temperature)?;
        Ok(())
    }

    /// Whether the group's light enters the image as it is.
    pub fn is_plain(&self) -> bool {
        self.enabled && self.scale == 1.0 && self.rgb_scale == Vec3::ONE && self.temperature <= 0.0
    }

    /// What the group's linear sRGB is multiplied by in the image (zero when disabled).
    pub fn weighing(&self) -> DMat3 {
        if !self.enabled {
            return DMat3::ZERO;
        }
        let white = linear_srgb_to_xyz(DVec3::ONE);
        let mut xyz = adaptation(white, linear_srgb_to_xyz(self.rgb_scale.as_dvec3()));
        if self.temperature > 0.0 {
            xyz *= adaptation(white, blackbody_xyz(self.temperature));
        }
        LINEAR_SRGB_TO_XYZ.inverse() * xyz * LINEAR_SRGB_TO_XYZ * f64::from(self.scale)
    }
}

/// LuxRender's colour adaptation from white `from` to white `to` (XYZ): the two whites'
/// channel ratios between the Bradford matrix and its inverse. A white of zero in a channel
/// adapts nothing there.
fn adaptation(from: DVec3, to: DVec3) -> DMat3 {
    let bradford = DMat3::from_cols_array(&[
        0.8951, -0.7502, 0.0389, 0.2664, 1.7135, -0.0685, -0.1614, 0.0367, 1.0296,
    ]);
    let ratio = DVec3::select(from.cmpne(DVec3::ZERO), to / from, DVec3::ZERO);
    bradford.inverse() * DMat3::from_diagonal(ratio) * bradford
}

/// A scene's light groups: each group's settings, and which group each `LightSource` is in.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightGroups {
    /// In the order they first appear; at most [`MAX_LIGHT_GROUPS`].
    pub groups: Vec<LightGroupDesc>,
    /// For each of the scene description's `LightSource` lights, in order, its group's index.
    pub of_sources: Vec<u8>,
}

impl LightGroups {
    /// Whether the film keeps a layer per group: two or more groups.
    pub fn layered(&self) -> bool {
        self.groups.len() >= 2
    }

    /// Weighs an image by the groups' settings, as the film's image is made: `linear` (the
    /// total light, rows top to bottom) untouched when every group is plain (or the groups'
    /// layers were not kept); a single group's
    /// weighing applied to all of it; else each pixel made the sum of each group's weighed
    /// light, `images` holding the groups' layers as `Film::light_group_images` gives them.
    pub fn weigh_image(&self, linear: &mut [Vec3], images: &[(String, Vec<Vec3>)]) {
        let layered = self.layered();
        if self.groups.iter().all(LightGroupDesc::is_plain) || layered && images.is_empty() {
            return;
        }
        let weighings: Vec<DMat3> = self.groups.iter().map(LightGroupDesc::weighing).collect();
        if !layered {
            for rgb in linear.iter_mut() {
                *rgb = weigh(&weighings[0], *rgb).as_vec3();
            }
            return;
        }
        for (i, rgb) in linear.iter_mut().enumerate() {
            *rgb = weighings
                .iter()
                .zip(images)
                .map(|(w, (_, group))| weigh(w, group[i]))
                .sum::<DVec3>()
                .as_vec3();
        }
    }
}

/// The linear sRGB the sRGB-to-sRGB matrix `m` makes of `rgb`.
pub fn weigh(m: &DMat3, rgb: Vec3) -> DVec3 {
    *m * rgb.as_dvec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DMat3, b: DMat3, tol: f64) -> bool {
        (a - b).to_cols_array().iter().all(|d| d.abs() < tol)
    }

    #[test]
    fn plain_groups_weigh_by_identity_and_scale_alone_scales() {
        let plain = LightGroupDesc::named("a");
        assert!(plain.is_plain());
        assert!(close(plain.weighing(), DMat3::IDENTITY, 1e-9));
        let scaled = LightGroupDesc {
            scale: 2.5,
            ..plain.clone()
        };
        assert!(close(scaled.weighing(), DMat3::IDENTITY * 2.5, 1e-9));
        let off = LightGroupDesc {
            enabled: false,
            ..plain
        };
        assert_eq!(off.weighing(), DMat3::ZERO);
    }

    /// LuxRender's adaptation is the white's XYZ ratios between the Bradford matrix and its
    /// inverse (not the ratios of the Bradford responses): a grey rgb scale is exactly that
    /// scale; a coloured one tints white towards it (red over green over blue for a warm one,
    /// though not exactly to it); a temperature near D65 is near white, a low one warm, a high
    /// one cool.
    #[test]
    fn rgb_scale_and_temperature_tint_white_as_luxrender_does() {
        let grey = LightGroupDesc {
            rgb_scale: Vec3::splat(0.25),
            ..LightGroupDesc::named("lamps")
        };
        assert!(close(grey.weighing(), DMat3::IDENTITY * 0.25, 1e-9));
        let warm = LightGroupDesc {
            rgb_scale: Vec3::new(1.0, 0.6, 0.3),
            ..LightGroupDesc::named("lamps")
        };
        let white = weigh(&warm.weighing(), Vec3::ONE);
        assert!(
            white.x > white.y && white.y > white.z && white.z > 0.2,
            "{white}"
        );
        assert!(
            (white - DVec3::new(0.804, 0.664, 0.307))
                .abs()
                .max_element()
                < 2e-3,
            "{white}"
        );
        let at = |t: f32| {
            let g = LightGroupDesc {
                temperature: t,
                ..LightGroupDesc::named("sun")
            };
            weigh(&g.weighing(), Vec3::ONE)
        };
        let (warm, d65, cool) = (at(2700.0), at(6504.0), at(12000.0));
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm}");
        assert!(cool.z > cool.x, "{cool}");
        assert!((d65 - DVec3::ONE).abs().max_element() < 0.06, "{d65}");
        // The rgb scale's matrix, then the temperature's, then the scale.
        let both = LightGroupDesc {
            rgb_scale: Vec3::new(1.0, 0.6, 0.3),
            temperature: 2700.0,
            scale: 2.0,
            ..LightGroupDesc::named("both")
        };
        let white_xyz = linear_srgb_to_xyz(DVec3::ONE);
        let to_xyz = LINEAR_SRGB_TO_XYZ;
        let expected = to_xyz.inverse()
            * adaptation(white_xyz, linear_srgb_to_xyz(both.rgb_scale.as_dvec3()))
            * adaptation(white_xyz, blackbody_xyz(2700.0))
            * to_xyz
            * 2.0;
        assert!(
            close(both.weighing(), expected, 1e-12),
            "{} vs {expected}",
            both.weighing()
        );
    }

    #[test]
    fn images_weigh_each_group_and_keep_a_plain_total() {
        let mut groups = LightGroups {
            groups: vec![LightGroupDesc::named("sun"), LightGroupDesc::named("lamps")],
            of_sources: vec![0, 1],
        };
        let layers = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 0.5, 0.5)];
        let images: Vec<(String, Vec<Vec3>)> =
            layers.iter().map(|&l| (String::new(), vec![l])).collect();
        let total = layers[0] + layers[1];
        let image = |groups: &LightGroups| {
            let mut linear = [total];
            groups.weigh_image(&mut linear, &images);
            linear[0]
        };
        assert_eq!(image(&groups), total);
        groups.groups[1].scale = 4.0;
        let weighed = image(&groups);
        assert!(
            (weighed - Vec3::new(3.0, 4.0, 5.0)).abs().max_element() < 1e-5,
            "{weighed}"
        );
        groups.groups[0].enabled = false;
        let weighed = image(&groups);
        assert!(
            (weighed - Vec3::splat(2.0)).abs().max_element() < 1e-5,
            "{weighed}"
        );
        // One group: its weighing is the whole image's.
        let single = LightGroups {
            groups: vec![LightGroupDesc {
                scale: 0.5,
                ..LightGroupDesc::named("default")
            }],
            of_sources: vec![0],
        };
        let mut linear = [total];
        single.weigh_image(&mut linear, &[]);
        assert!((linear[0] - total * 0.5).abs().max_element() < 1e-6);
    }
}
