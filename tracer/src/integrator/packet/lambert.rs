//! A packet's Lambert vertices in lanes: the BSDF's sample and the light sample with its
//! weight, each lane the bits of [`Vertex`](crate::integrator::vertex::Vertex)'s for its path.

use glam::{Vec2, Vec3};

use super::vectors::{is_zero, lanes_set, mask_of, LaneVec3s};
use crate::bxdf::local::cosine_hemisphere;
use crate::integrator::mis::power_heuristic;
use crate::integrator::scene::PathScene;
use crate::integrator::shadow::shadow_tmax_in_lanes;
use crate::lanes::{Lanes, MAX_LANES};
use crate::lights::LightSamples;
use crate::math::Ray;
use crate::vec3_lanes::{dot, negate, offset_origin, scale, select3, times, V3};

/// The Lambert vertices of a packet's live lanes: what [`Bsdf`] holds of a bare Lambert one.
pub(super) struct LambertVertex<L: Lanes> {
    pub(super) p: V3<L>,
    pub(super) ng: V3<L>,
    pub(super) ns: V3<L>,
    pub(super) frame: [V3<L>; 3],
    pub(super) f: V3<L>,
    /// `-ray.dir`, the direction the path arrived from.
    pub(super) wo: V3<L>,
    /// `wo` in the shading frame.
    pub(super) wo_local: V3<L>,
}

/// A BSDF sample of a packet's Lambert vertices.
pub(super) struct LambertSample<L: Lanes> {
    pub(super) wi: V3<L>,
    pub(super) pdf: L,
    /// Where the sample is a direction the path may take (else the scalar code finds none).
    pub(super) valid: L::M,
}

impl<L: Lanes> LambertVertex<L> {
    /// The shading normal on `wo`'s side ([`Bsdf::gathers_from`]).
    #[inline(always)]
    pub(super) fn facing(&self) -> V3<L> {
        let n = self.frame[2];
        select3(self.wo_local[2].lt(L::splat(0.0)), negate(n), n)
    }

    /// [`Bsdf::sample`] of a Lambert lobe, with [`DiffuseReflection::sample`]'s checks.
    ///
    /// [`DiffuseReflection::sample`]: crate::bxdf::diffuse::DiffuseReflection::sample
    #[inline(always)]
    pub(super) fn sample(&self, u: [L; 2]) -> LambertSample<L> {
        let zero = L::splat(0.0);
        let wo_z = self.wo_local[2];
        let mirrored = wo_z.lt(zero);
        // The lobe mirrors a query from below to the upper hemisphere and back.
        let [x, y, z] = cosine_hemisphere(u);
        let wo_up = L::select(mirrored, L::splat(-1.0) * wo_z, wo_z);
        let same_hemisphere = zero.lt(wo_up * z);
        let pdf = L::select(
            same_hemisphere,
            z.abs() * L::splat(std::f32::consts::FRAC_1_PI),
            zero,
        );
        let z = L::select(mirrored, L::splat(-1.0) * z, z);
        let [s, t, n] = self.frame;
        let world = [
            s[0] * x + t[0] * y + n[0] * z,
            s[1] * x + t[1] * y + n[1] * z,
            s[2] * x + t[2] * y + n[2] * z,
        ];
        let wi = scale(world, L::splat(1.0) / dot(world, world).sqrt());
        // The geometric and shading normals agree on the sides of wo and wi.
        let geometric = dot(self.wo, self.ng) * dot(wi, self.ng);
        let shading = wo_z * z;
        let agree =
            (zero.lt(geometric) & zero.lt(shading)) | (geometric.lt(zero) & shading.lt(zero));
        LambertSample {
            wi,
            pdf,
            valid: agree & same_hemisphere & zero.lt(pdf),
        }
    }
}

impl<L: Lanes> LambertVertex<L> {
    /// [`direct_light`] at the vertices of the lanes `lanes` sets, with `draw`'s light choice
    /// numbers and share: in lanes, but the shadow rays (counted in `rays`) and, unless the
    /// lights are a few plain triangle lamps ([`TriangleLamps`]), the light's choice and point.
    ///
    /// [`TriangleLamps`]: crate::lights::TriangleLamps
    #[inline(always)]
    pub(super) fn direct_light<S: PathScene>(
        &self,
        scene: &S,
        lanes: &[bool; MAX_LANES],
        rays: &mut [u32; MAX_LANES],
        draw: &LightDraws,
        u: [L; 2],
        bsdf_count: f32,
    ) -> V3<L> {
        let zero = L::splat(0.0);
        let light = match scene.lights().triangle_lamps() {
            Some(lamps) => {
                let s = lamps.sample(self.p, L::load(&draw.u_select), u);
                let pdf = L::select(mask_of::<L>(lanes), s.pdf, zero);
                LightSamples { pdf, ..s }
            }
            None => self.light_one_lane_at_a_time(scene, lanes, draw, u),
        };
        let LightSamples {
            wi,
            li,
            pdf,
            dist,
            delta,
        } = light;
        let pdf = pdf * L::load(&draw.share);
        let dark: L::M = is_zero(li[0]) & is_zero(li[1]) & is_zero(li[2]);
        let lit = !pdf.le(zero) & !dark;
        // The BSDF's value: Lambert's where the normals agree and wo and wi share a side.
        let wi_z = dot(wi, self.frame[2]);
        let geometric = dot(self.wo, self.ng) * dot(wi, self.ng);
        let shading = self.wo_local[2] * wi_z;
        let agree =
            (zero.lt(geometric) & zero.lt(shading)) | (geometric.lt(zero) & shading.lt(zero));
        let reflects = agree & zero.lt(shading);
        let origin = offset_origin(self.p, self.ng, wi);
        let tmax = shadow_tmax_in_lanes(self.p, origin, dist).values();
        let tested = lanes_set::<L>(lit & reflects);
        let (origin, dir) = (LaneVec3s::of(origin), LaneVec3s::of(wi));
        let mut visible = [0.0; MAX_LANES];
        for i in 0..L::N {
            if lanes[i] && tested[i] {
                rays[i] += 1;
                let blocked = scene
                    .geometry()
                    .occluded(&Ray::new(origin.get(i), dir.get(i)), tmax[i]);
                visible[i] = if blocked { 0.0 } else { 1.0 };
            }
        }
        let bsdf_pdf = L::select(
            zero.lt(shading),
            wi_z.abs() * L::splat(std::f32::consts::FRAC_1_PI),
            zero,
        );
        let heuristic = power_heuristic(pdf, L::splat(bsdf_count) * bsdf_pdf);
        let weight = L::select(zero.lt(delta), L::splat(1.0), heuristic);
        let k = dot(wi, self.ns).abs() * weight / pdf;
        let light = scale(times(self.f, li), k);
        let shown = zero.lt(L::load(&visible));
        [
            L::select(shown, light[0], zero),
            L::select(shown, light[1], zero),
            L::select(shown, light[2], zero),
        ]
    }

    /// The lights' samples ([`super::path::PathScene::lights`]' `sample`) of the lanes `lanes`
    /// sets, one lane at a time (a density of 0 where there is none).
    #[inline(always)]
    pub(super) fn light_one_lane_at_a_time<S: PathScene>(
        &self,
        scene: &S,
        lanes: &[bool; MAX_LANES],
        draw: &LightDraws,
        u: [L; 2],
    ) -> LightSamples<L> {
        let (p, facing) = (LaneVec3s::of(self.p), LaneVec3s::of(self.facing()));
        let (select, ux, uy) = (draw.u_select, u[0].values(), u[1].values());
        let mut wi = LaneVec3s::splat(Vec3::Z);
        let mut li = LaneVec3s::splat(Vec3::ZERO);
        let (mut pdf, mut dist, mut delta) = ([0.0; MAX_LANES], [0.0; MAX_LANES], [0.0; MAX_LANES]);
        for i in 0..L::N {
            if !lanes[i] {
                continue;
            }
            let u = Vec2::new(ux[i], uy[i]);
            // No sample: a density of 0, which ends the lane's light sample as `direct_light`.
            let (at, side) = (p.get(i), Some(facing.get(i)));
            if let Some(ls) = scene.lights().sample(at, side, select[i], u) {
                (pdf[i], dist[i]) = (ls.pdf, ls.dist);
                wi.set(i, ls.wi);
                li.set(i, ls.li);
                delta[i] = if ls.delta { 1.0 } else { 0.0 };
            }
        }
        LightSamples {
            wi: wi.load::<L>(),
            li: li.load::<L>(),
            pdf: L::load(&pdf),
            dist: L::load(&dist),
            delta: L::load(&delta),
        }
    }
}

/// The light choice numbers and shares of a packet's lane light samples
/// ([`super::path::LightDraw`]'s).
pub(super) struct LightDraws {
    pub(super) u_select: [f32; MAX_LANES],
    pub(super) share: [f32; MAX_LANES],
}
