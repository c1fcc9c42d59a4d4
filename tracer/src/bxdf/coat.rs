//! A glossy coat: the clear layer of LuxRender's Glossy2 (glossy, glossytranslucent,
//! glossycoating) and carpaint's three flake lobes. What lies under it is another lobe;
//! [`coat_over_base`](super::coat_over_base) puts the two together.
//!
//! - Up to [`MAX_LOBES`] GGX microfacet reflections, each with Schlick's Fresnel from its own
//!   normal-incidence reflectance `r0` and scaled by a `weight` (1 for glossy, whose Ks is
//!   `r0`; Ks1-3 for carpaint, whose R1-3 are `r0`). A lobe with zero roughness is a specular
//!   reflection. The coat reflects F(cos) = sum of weight * Schlick(cos, r0), at most the sum
//!   of the weights, which readers keep within 1.
//! - Absorption in the layer, exp(-Ka d (1/cos_i + 1/cos_o)) (LuxRender's
//!   CoatingAbsorption), applied to what passes through it.
//! - multibounce: the energy the coat's masking and shadowing remove is returned as a diffuse
//!   lobe coloured by the coat's average Fresnel (Kulla and Conty 2017), where LuxRender adds
//!   an ad-hoc (1 - G) term.
//!
//! All directions here are in the upper hemisphere: the coating mirrors queries to it.

use glam::{Vec2, Vec3};

use super::fresnel;
use super::ggx_albedo;
use super::local::reflect;
use super::microfacet::TrowbridgeReitz;

/// Carpaint's three lobes; glossy uses one.
pub const MAX_LOBES: usize = 3;

/// Cosine-weighted hemispherical average of Schlick's Fresnel: 2 * integral F(mu) mu dmu.
fn schlick_average(r0: Vec3) -> Vec3 {
    r0 + (Vec3::ONE - r0) / 21.0
}

/// One microfacet reflection of the coat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoatLobe {
    pub weight: Vec3,
    pub r0: Vec3,
    /// None: a specular reflection.
    pub distrib: Option<TrowbridgeReitz>,
}

impl CoatLobe {
    fn fresnel(&self, cos: f32) -> Vec3 {
        self.weight * fresnel::schlick(cos, self.r0)
    }

    /// How often this lobe is sampled, seen from `cos_o`.
    fn selection(&self, cos_o: f32) -> f32 {
        self.fresnel(cos_o).element_sum()
    }
}

/// A sampled direction of the coat alone.
pub enum CoatSample {
    /// A rough lobe's direction: the caller evaluates the whole BSDF there.
    Glossy(Vec3),
    /// A smooth lobe's mirror direction with its f and discrete probability within the coat.
    Specular { wi: Vec3, f: Vec3, probability: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat {
    lobes: [CoatLobe; MAX_LOBES],
    count: usize,
    /// Absorption coefficient of the layer and its thickness.
    pub ka: Vec3,
    pub depth: f32,
    /// Isotropic roughness for the multibounce term; None when multibounce is off.
    pub multibounce_alpha: Option<f32>,
}

impl Coat {
    /// A coat of the given lobes (at most [`MAX_LOBES`]; more are ignored). The weights are
    /// scaled down where their sum exceeds 1 in a channel, so the coat never reflects more than
    /// arrives.
    pub fn new(lobes: &[CoatLobe], ka: Vec3, depth: f32, multibounce_alpha: Option<f32>) -> Self {
        let idle = CoatLobe {
            weight: Vec3::ZERO,
            r0: Vec3::ZERO,
            distrib: None,
        };
        let mut all = [idle; MAX_LOBES];
        let count = lobes.len().min(MAX_LOBES);
        all[..count].copy_from_slice(&lobes[..count]);
        let total: Vec3 = all.iter().map(|l| l.weight).sum();
        let scale = Vec3::ONE / total.max(Vec3::ONE);
        for lobe in &mut all {
            lobe.weight *= scale;
        }
        Self {
            lobes: all,
            count,
            ka,
            depth: depth.max(0.0),
            multibounce_alpha,
        }
    }

    /// Glossy's coat: one lobe of weight 1 with normal-incidence reflectance `ks`.
    pub fn single(
        ks: Vec3,
        distrib: Option<TrowbridgeReitz>,
        ka: Vec3,
        depth: f32,
        multibounce_alpha: Option<f32>,
    ) -> Self {
        let lobe = CoatLobe {
            weight: Vec3::ONE,
            r0: ks,
            distrib,
        };
        Self::new(&[lobe], ka, depth, multibounce_alpha)
    }

    fn lobes(&self) -> &[CoatLobe] {
        &self.lobes[..self.count]
    }

    /// True when every lobe is a specular reflection.
    pub fn is_smooth(&self) -> bool {
        self.lobes().iter().all(|l| l.distrib.is_none())
    }

    /// The fraction of the light arriving at `cos` that the coat reflects.
    pub fn fresnel(&self, cos: f32) -> Vec3 {
        self.lobes().iter().map(|l| l.fresnel(cos)).sum()
    }

    /// The cosine-weighted hemispherical average of [`Coat::fresnel`].
    pub fn average_fresnel(&self) -> Vec3 {
        self.lobes()
            .iter()
            .map(|l| l.weight * schlick_average(l.r0))
            .sum()
    }

    /// Transmittance of the layer for a path entering at `cos_a` and leaving at `cos_b`.
    pub fn absorption(&self, cos_a: f32, cos_b: f32) -> Vec3 {
        if self.depth > 0.0 && self.ka != Vec3::ZERO {
            let path = self.depth * (cos_a + cos_b) / (cos_a * cos_b);
            (-self.ka * path).exp()
        } else {
            Vec3::ONE
        }
    }

    /// Transmittance of one crossing at `cos` (a path that leaves through the other face).
    pub fn absorption_once(&self, cos: f32) -> Vec3 {
        if self.depth > 0.0 && self.ka != Vec3::ZERO {
            (-self.ka * (self.depth / cos)).exp()
        } else {
            Vec3::ONE
        }
    }

    fn multibounce_f(&self, alpha: f32, cos_o: f32, cos_i: f32) -> Vec3 {
        let e_avg = ggx_albedo::average_albedo(alpha);
        if e_avg >= 1.0 {
            return Vec3::ZERO;
        }
        let lost =
            (1.0 - ggx_albedo::albedo(alpha, cos_o)) * (1.0 - ggx_albedo::albedo(alpha, cos_i));
        // Average Fresnel over the hemisphere, and the colour after many bounces.
        let f_avg = self.average_fresnel();
        let f_ms = f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
        f_ms * (lost * std::f32::consts::FRAC_1_PI / (1.0 - e_avg))
    }

    /// The coat's own reflection (its rough lobes) for `wo`, `wi` in the upper hemisphere.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o <= 0.0 || cos_i <= 0.0 {
            return Vec3::ZERO;
        }
        let wm = (wo + wi).normalize();
        let mut f = Vec3::ZERO;
        for lobe in self.lobes() {
            if let Some(distrib) = lobe.distrib {
                f += lobe.fresnel(wo.dot(wm))
                    * (distrib.d(wm) * distrib.g(wo, wi) / (4.0 * cos_o * cos_i));
            }
        }
        if let Some(alpha) = self.multibounce_alpha {
            f += self.multibounce_f(alpha, cos_o, cos_i);
        }
        f
    }

    /// Density of [`Coat::sample`]'s glossy directions (over all lobes, smooth ones included
    /// in the total).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let total: f32 = self.lobes().iter().map(|l| l.selection(wo.z)).sum();
        if total <= 0.0 {
            return 0.0;
        }
        let wm = (wo + wi).normalize();
        self.lobes()
            .iter()
            .filter_map(|l| {
                let distrib = l.distrib?;
                Some(l.selection(wo.z) * distrib.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs()))
            })
            .sum::<f32>()
            / total
    }

    /// Picks a lobe with `u_lobe` (in proportion to what each reflects at `wo`) and samples
    /// its direction with `u`.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<CoatSample> {
        let selections = self.lobes().iter().map(|l| l.selection(wo.z));
        let total: f32 = selections.clone().sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let mut target = u_lobe * total;
        let mut chosen = self.lobes().last()?;
        for (lobe, s) in self.lobes().iter().zip(selections) {
            if target < s {
                chosen = lobe;
                break;
            }
            target -= s;
        }
        match chosen.distrib {
            Some(distrib) => Some(CoatSample::Glossy(reflect(wo, distrib.sample_wm(wo, u)))),
            None => {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                Some(CoatSample::Specular {
                    wi,
                    f: chosen.fresnel(wo.z) / wi.z,
                    probability: chosen.selection(wo.z) / total,
                })
            }
        }
    }
}
