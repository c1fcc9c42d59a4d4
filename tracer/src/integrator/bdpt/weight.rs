//! Multiple importance sampling over every strategy that makes a path of the same length: the
//! power heuristic's weight of the strategy that made it, from the ratios of the densities of
//! its vertices as each side samples them (Veach 1997, 10.2; pbrt-v4's `MISWeight`).

use super::vertex::PathVertex;

/// One vertex's densities as a strategy's weight sees them.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Densities {
    pub(super) fwd: f32,
    pub(super) rev: f32,
    pub(super) delta: bool,
}

impl From<&PathVertex> for Densities {
    fn from(v: &PathVertex) -> Self {
        Self {
            fwd: v.pdf_fwd,
            rev: v.pdf_rev,
            delta: v.delta,
        }
    }
}

/// The strategies the subpaths' lengths allow: a path of `s` light and `t` camera vertices
/// can be made by any split of its vertices whose light part has at most `max_light` and
/// camera part at most `max_camera` vertices. The camera part has at least one vertex (no
/// light subpath reaches a lens); the light part's first vertex is never connected straight to
/// the camera (`s = 1, t = 1`: a lamp seen directly is the camera path's).
#[derive(Clone, Copy, Debug)]
pub(super) struct Limits {
    pub(super) max_light: usize,
    pub(super) max_camera: usize,
    /// The one strategy (s, t) that counts, at full weight, instead of MIS over all of them:
    /// what tests compare each strategy's image with ([`super::BidirectionalScene::only_strategy`]).
    pub(super) only: Option<(usize, usize)>,
}

/// The power heuristic's weight of the strategy joining light vertices `light` (`s` of them,
/// the connection vertex last) and camera vertices `camera` (`t`, the connection vertex last),
/// with their densities as the connection left them; `delta_light`: the light vertex is a
/// delta light (no path hits it).
pub(super) fn mis_weight(
    light: &[Densities],
    camera: &[Densities],
    delta_light: bool,
    limits: Limits,
) -> f32 {
    let (s, t) = (light.len(), camera.len());
    if let Some(only) = limits.only {
        return if only == (s, t) { 1.0 } else { 0.0 };
    }
    if s + t == 2 {
        return 1.0;
    }
    // A density of zero next to a delta vertex (a specular bounce samples its neighbours with
    // a delta density, which the vertex records as zero) counts as one: such ratios cancel,
    // and the strategies that would connect at a delta vertex are skipped below. A reverse
    // density of zero anywhere else is a vertex the other side cannot make (a light at
    // infinity beyond its disc: an infinite plane reaches past the scene's bounds; a BSDF's
    // side that sends nothing back): no strategy past it can make the path.
    let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
    let mut sum = 0.0f32;
    // Moving the connection toward the camera: camera vertex i becomes the light part's last.
    let mut ratio = 1.0f32;
    for i in (1..t).rev() {
        let after_delta = i + 1 < t && camera[i + 1].delta;
        if camera[i].rev == 0.0 && !after_delta {
            break;
        }
        ratio *= remap(camera[i].rev) / remap(camera[i].fwd);
        let (light_part, camera_part) = (s + t - i, i);
        let possible = light_part <= limits.max_light && !(light_part == 1 && camera_part == 1);
        if possible && !camera[i].delta && !camera[i - 1].delta {
            sum += ratio * ratio;
        }
    }
    // Moving it toward the light: light vertex i becomes the camera part's last.
    let mut ratio = 1.0f32;
    for i in (0..s).rev() {
        let after_delta = i + 1 < s && light[i + 1].delta;
        if light[i].rev == 0.0 && !after_delta {
            break;
        }
        ratio *= remap(light[i].rev) / remap(light[i].fwd);
        let camera_part = s + t - i;
        let before_is_delta = if i > 0 {
            light[i - 1].delta
        } else {
            delta_light
        };
        if camera_part <= limits.max_camera && !light[i].delta && !before_is_delta {
            sum += ratio * ratio;
        }
    }
    let w = 1.0 / (1.0 + sum);
    if w.is_finite() {
        w
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path of `k` vertices (0 on the light, k - 1 the camera's lens), each with the density
    /// of the light side reaching it and of the camera side reaching it: the split of every
    /// strategy `s + t = k` sees them as its subpaths would.
    fn split(
        light_side: &[f32],
        camera_side: &[f32],
        s: usize,
    ) -> (Vec<Densities>, Vec<Densities>) {
        let k = light_side.len();
        let light = (0..s)
            .map(|i| Densities {
                fwd: light_side[i],
                rev: camera_side[i],
                delta: false,
            })
            .collect();
        let camera = (s..k)
            .rev()
            .map(|i| Densities {
                fwd: camera_side[i],
                rev: light_side[i],
                delta: false,
            })
            .collect();
        (light, camera)
    }

    /// The weights of all the strategies that can make one path sum to one, with the subpath
    /// limits cutting some away, for paths of every length up to 10.
    #[test]
    fn the_weights_of_a_paths_strategies_sum_to_one() {
        let mut rng = fastrand::Rng::with_seed(3);
        for k in 3..=10 {
            for (max_light, max_camera) in [(20, 20), (3, 20), (20, 4), (4, 5)] {
                let limits = Limits {
                    max_light,
                    max_camera,
                    only: None,
                };
                for _ in 0..200 {
                    let light_side: Vec<f32> = (0..k).map(|_| 0.01 + 5.0 * rng.f32()).collect();
                    let camera_side: Vec<f32> = (0..k).map(|_| 0.01 + 5.0 * rng.f32()).collect();
                    let mut total = 0.0;
                    let mut strategies = 0;
                    for s in 0..k {
                        let t = k - s;
                        if s > max_light || t > max_camera || (s == 1 && t == 1) {
                            continue;
                        }
                        let (light, camera) = split(&light_side, &camera_side, s);
                        total += mis_weight(&light, &camera, false, limits);
                        strategies += 1;
                    }
                    if strategies > 0 {
                        assert!((total - 1.0).abs() < 1e-4, "k {k} {limits:?}: {total}");
                    }
                }
            }
        }
    }

    /// A specular vertex takes no connection: the strategies left still sum to one. As the
    /// walk records it, its neighbours' densities of being sampled through it are zero.
    #[test]
    fn a_delta_vertex_leaves_the_other_strategies_summing_to_one() {
        let k = 6;
        let mut light_side = [0.7, 1.3, 2.0, 0.4, 3.1, 1.0];
        let mut camera_side = [1.1, 0.2, 0.9, 2.2, 0.5, 1.0];
        let specular = 3;
        light_side[specular + 1] = 0.0;
        camera_side[specular - 1] = 0.0;
        let limits = Limits {
            max_light: 10,
            max_camera: 10,
            only: None,
        };
        let mut total = 0.0;
        for s in 0..k {
            let t = k - s;
            // A strategy joining at the specular vertex (it is the last of either part) is
            // impossible.
            if s == 1 && t == 1 || s == specular + 1 || s == specular {
                continue;
            }
            let (mut light, mut camera) = split(&light_side, &camera_side, s);
            if let Some(d) = light.get_mut(specular) {
                d.delta = true;
            }
            if let Some(d) = camera.get_mut(k - 1 - specular) {
                d.delta = true;
            }
            total += mis_weight(&light, &camera, false, limits);
        }
        assert!((total - 1.0).abs() < 1e-4, "{total}");
    }

    /// A vertex one side cannot make (its density from that side is zero: a light at infinity
    /// beyond its disc) leaves the strategies that do not need that side to make it summing to
    /// one, and gives the others nothing.
    #[test]
    fn a_vertex_one_side_cannot_make_leaves_the_others_summing_to_one() {
        let k = 6;
        let mut light_side = [0.7, 1.3, 2.0, 0.4, 3.1, 1.0];
        let camera_side = [1.1, 0.2, 0.9, 2.2, 0.5, 1.0];
        // No light subpath reaches vertex 2: strategies with s > 2 light vertices need one.
        let unreachable = 2;
        light_side[unreachable] = 0.0;
        let limits = Limits {
            max_light: 10,
            max_camera: 10,
            only: None,
        };
        let mut total = 0.0;
        for s in 0..=unreachable {
            let t = k - s;
            if s == 1 && t == 1 {
                continue;
            }
            let (light, camera) = split(&light_side, &camera_side, s);
            total += mis_weight(&light, &camera, false, limits);
        }
        assert!((total - 1.0).abs() < 1e-4, "{total}");
    }
}
