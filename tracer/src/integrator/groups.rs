//! Light groups in the path tracer: each light term a path adds is credited to the light group
//! of the light it came from (`film::light_groups`), so the film keeps each group's light
//! apart. A render without group layers passes `()`, which credits nothing: its walk compiles
//! to what it was, with the same bits.

use glam::Vec3;

use crate::film::light_groups::MAX_LIGHT_GROUPS;
use crate::lights::{Emitter, Lights};

/// Where a light term came from: a light of the list, the lights at infinity along a
/// direction (towards them), or the light a light sample chose with `u_select` and reached
/// along `wi` (looked up only when a sink keeps groups, so a render without them pays nothing).
#[derive(Clone, Copy, Debug)]
pub(super) enum LitBy {
    Light(u32),
    /// The area light of a shape.
    Shape(u32),
    Environment(Vec3),
    Choice {
        u_select: f32,
        wi: Vec3,
    },
}

/// A light term of a vertex's light sample, and where it came from (None when it is zero).
#[derive(Clone, Copy, Debug)]
pub(super) struct LightTerm {
    pub(super) light: Vec3,
    pub(super) from: Option<LitBy>,
}

impl LightTerm {
    pub(super) const NONE: Self = Self {
        light: Vec3::ZERO,
        from: None,
    };
}

/// What a path's light terms are credited to.
pub trait GroupSink {
    /// Whether it keeps anything (false: the walk skips the crediting altogether).
    const ON: bool;

    fn add(&mut self, group: u8, light: Vec3);
}

impl GroupSink for () {
    const ON: bool = false;

    #[inline(always)]
    fn add(&mut self, _: u8, _: Vec3) {}
}

/// A path's light per light group.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GroupRadiance(pub [Vec3; MAX_LIGHT_GROUPS]);

impl GroupSink for GroupRadiance {
    const ON: bool = true;

    fn add(&mut self, group: u8, light: Vec3) {
        if let Some(sum) = self.0.get_mut(usize::from(group)) {
            *sum += light;
        }
    }
}

/// Credits `light`, a light term that came from `from`, to its group: where the lights at
/// infinity are in several groups, each gets the share of `light` its radiance has of theirs
/// along the term's direction, channel by channel.
#[inline(always)]
pub(super) fn credit<G: GroupSink>(
    sink: &mut G,
    lights: &Lights,
    from: Option<LitBy>,
    light: Vec3,
) {
    let Some(from) = from.filter(|_| G::ON && light != Vec3::ZERO) else {
        return;
    };
    let (emitter, dir) = match from {
        LitBy::Light(index) => (Emitter::Light(index), Vec3::ZERO),
        LitBy::Shape(shape) => match lights.emitter_of_shape(shape) {
            Some(emitter) => (emitter, Vec3::ZERO),
            None => return,
        },
        LitBy::Environment(dir) => (Emitter::Environment, dir),
        LitBy::Choice { u_select, wi } => match lights.chosen_emitter(u_select) {
            Some(emitter) => (emitter, wi),
            None => return,
        },
    };
    match (lights.light_group(emitter), emitter) {
        (Some(group), _) => sink.add(group, light),
        (None, Emitter::Environment) => {
            let total = lights.environment(dir);
            lights.environment_by_group(dir, |group, le| {
                let share = Vec3::select(total.cmpgt(Vec3::ZERO), le / total, Vec3::ZERO);
                sink.add(group, light * share);
            });
        }
        (None, Emitter::Light(_)) => {}
    }
}
