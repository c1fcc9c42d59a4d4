//! Whether two images of one render differ visibly, pixel by pixel: Yee's perceptual metric
//! (H. Yee, "A perceptual metric for production testing", Journal of Graphics Tools 9(4),
//! 2004), the comparison LuxRender 1.x runs between successive images of a render for its
//! Film's `haltthreshold`.
//!
//! Both images are display values in [0, 1] (tone-mapped and gamma encoded, as the PNG is
//! written, before quantisation), seen on a 100 cd/m^2 display across a 45 degree field of view,
//! LuxRender's viewing conditions. A pixel differs visibly when its luminance changed by more
//! than the threshold of visibility at its adaptation luminance (Ward Larson's TVI), raised by
//! visual masking where the image has contrast at the spatial frequencies the eye is least
//! sensitive to (Barten's contrast sensitivity, Daly's masking); or, in photopic regions, when
//! its colour (CIE L*a*b* chroma) changed by more than the same factor.
//!
//! The luminance pyramid is kept whole: [`memory_bytes`] is what a comparison takes, which the
//! coordinator counts in the film's memory budget.

use std::f32::consts::PI;

/// Levels of the luminance pyramid: each the previous blurred once by [`KERNEL`].
const LEVELS: usize = 8;
/// The separable blur between levels (a binomial-like 5-tap kernel).
const KERNEL: [f32; 5] = [0.05, 0.25, 0.4, 0.25, 0.05];
/// The viewing conditions LuxRender compares under.
const FIELD_OF_VIEW_DEGREES: f32 = 45.0;
const DISPLAY_GAMMA: f32 = 2.2;
const DISPLAY_LUMINANCE: f32 = 100.0;
/// Below this adaptation luminance (cd/m^2, scotopic vision) colour is not compared.
const COLOUR_ADAPTATION: f32 = 10.0;
/// The smallest denominator, contrast sum and adaptation luminance the metric divides by.
const TINY: f32 = 1e-5;

/// Bytes [`count_visible_differences`] allocates for an image of `pixels`: two luminance
/// pyramids and a scratch row set.
pub fn memory_bytes(pixels: u64) -> u64 {
    pixels * (2 * LEVELS as u64 + 1) * std::mem::size_of::<f32>() as u64
}

/// How many pixels of `a` and `b` (display RGB in [0, 1], rows of `width`) differ visibly.
///
/// # Panics
///
/// If either image does not hold `width` x `height` pixels.
pub fn count_visible_differences(
    a: &[[f32; 3]],
    b: &[[f32; 3]],
    width: usize,
    height: usize,
) -> u64 {
    assert_eq!(a.len(), width * height, "image a is not {width}x{height}");
    assert_eq!(b.len(), width * height, "image b is not {width}x{height}");
    if a == b {
        return 0;
    }
    let pyramid_a = Pyramid::of_luminance(a, width, height);
    let pyramid_b = Pyramid::of_luminance(b, width, height);
    let viewing = Viewing::of(width);
    let mut failed = 0;
    for i in 0..width * height {
        let visible = viewing.luminance_differs(&pyramid_a, &pyramid_b, i, |adapt, factor| {
            adapt >= COLOUR_ADAPTATION && chroma_distance(a[i], b[i]) > factor
        });
        failed += u64::from(visible);
    }
    failed
}

/// Luminance (cd/m^2) blurred level after level, every level at full resolution.
struct Pyramid {
    levels: Vec<Vec<f32>>,
}

impl Pyramid {
    fn of_luminance(image: &[[f32; 3]], width: usize, height: usize) -> Self {
        let base: Vec<f32> = image
            .iter()
            .map(|&rgb| xyz(linear(rgb))[1] * DISPLAY_LUMINANCE)
            .collect();
        let mut levels = Vec::with_capacity(LEVELS);
        levels.push(base);
        let mut scratch = vec![0.0f32; width * height];
        for _ in 1..LEVELS {
            let previous = levels.last().expect("level 0 is there");
            let mut next = vec![0.0f32; width * height];
            blur_rows(previous, &mut scratch, width, height);
            blur_columns(&scratch, &mut next, width, height);
            levels.push(next);
        }
        Self { levels }
    }

    fn at(&self, level: usize, i: usize) -> f32 {
        self.levels[level][i]
    }
}

/// A coordinate reflected into 0..len at the image's edges (`-1` reads 1, `len` reads len-2).
fn reflect(i: isize, len: usize) -> usize {
    let len = len as isize;
    let i = if i < 0 { -i } else { i };
    let i = if i >= len { 2 * len - i - 2 } else { i };
    i.clamp(0, len - 1) as usize
}

fn blur_rows(src: &[f32], dst: &mut [f32], width: usize, height: usize) {
    for y in 0..height {
        let row = &src[y * width..(y + 1) * width];
        for x in 0..width {
            dst[y * width + x] = KERNEL
                .iter()
                .enumerate()
                .map(|(k, w)| w * row[reflect(x as isize + k as isize - 2, width)])
                .sum();
        }
    }
}

fn blur_columns(src: &[f32], dst: &mut [f32], width: usize, height: usize) {
    for y in 0..height {
        for x in 0..width {
            dst[y * width + x] = KERNEL
                .iter()
                .enumerate()
                .map(|(k, w)| w * src[reflect(y as isize + k as isize - 2, height) * width + x])
                .sum();
        }
    }
}

/// What the viewing conditions fix for every pixel: the spatial frequency of each pyramid
/// level, the eye's relative insensitivity there, and the level the eye adapts at (about one
/// degree of the field).
struct Viewing {
    cycles_per_degree: [f32; LEVELS],
    frequency_factor: [f32; LEVELS - 2],
    adaptation_level: usize,
}

impl Viewing {
    fn of(width: usize) -> Self {
        let half_angle = FIELD_OF_VIEW_DEGREES * 0.5 * PI / 180.0;
        let one_degree_pixels = 2.0 * libm::tanf(half_angle) * 180.0 / PI;
        let pixels_per_degree = width as f32 / one_degree_pixels;
        let mut adaptation_level = LEVELS - 1;
        let mut span = 1.0f32;
        for level in 0..LEVELS {
            if span > one_degree_pixels {
                adaptation_level = level;
                break;
            }
            span *= 2.0;
        }
        let mut cycles_per_degree = [0.0f32; LEVELS];
        cycles_per_degree[0] = 0.5 * pixels_per_degree;
        for level in 1..LEVELS {
            cycles_per_degree[level] = 0.5 * cycles_per_degree[level - 1];
        }
        let peak = contrast_sensitivity(3.248, 100.0);
        let frequency_factor = std::array::from_fn(|level| {
            peak / contrast_sensitivity(cycles_per_degree[level], 100.0)
        });
        Self {
            cycles_per_degree,
            frequency_factor,
            adaptation_level,
        }
    }

    /// Whether pixel `i` differs visibly: its luminance change above the masked threshold, or
    /// `colour_differs(adaptation luminance, masking factor)`.
    fn luminance_differs(
        &self,
        a: &Pyramid,
        b: &Pyramid,
        i: usize,
        colour_differs: impl Fn(f32, f32) -> bool,
    ) -> bool {
        let mut contrast = [0.0f32; LEVELS - 2];
        for (level, c) in contrast.iter_mut().enumerate() {
            let band = |p: &Pyramid| (p.at(level, i) - p.at(level + 1, i)).abs();
            let numerator = band(a).max(band(b));
            let denominator = a
                .at(level + 2, i)
                .abs()
                .max(b.at(level + 2, i).abs())
                .max(TINY);
            *c = numerator / denominator;
        }
        let contrast_sum = contrast.iter().sum::<f32>().max(TINY);
        let adapt =
            (0.5 * (a.at(self.adaptation_level, i) + b.at(self.adaptation_level, i))).max(TINY);
        let factor = contrast
            .iter()
            .enumerate()
            .map(|(level, &c)| {
                let masking =
                    masking(c * contrast_sensitivity(self.cycles_per_degree[level], adapt));
                c * self.frequency_factor[level] * masking / contrast_sum
            })
            .sum::<f32>()
            .clamp(1.0, 10.0);
        let delta = (a.at(0, i) - b.at(0, i)).abs();
        delta > factor * threshold_of_visibility(adapt) || colour_differs(adapt, factor)
    }
}

/// The smallest visible luminance change at an adaptation luminance (cd/m^2): Ward Larson,
/// Rushmeier and Piatko's threshold-versus-intensity function (1997).
fn threshold_of_visibility(adaptation: f32) -> f32 {
    let log_a = libm::log10f(adaptation);
    let log_threshold = if log_a < -3.94 {
        -2.86
    } else if log_a < -1.44 {
        libm::powf(0.405 * log_a + 1.6, 2.18) - 2.86
    } else if log_a < -0.0184 {
        log_a - 0.395
    } else if log_a < 1.9 {
        libm::powf(0.249 * log_a + 0.65, 2.7) - 0.72
    } else {
        log_a - 1.255
    };
    libm::powf(10.0, log_threshold)
}

/// Barten's contrast sensitivity (1989) at a spatial frequency (cycles per degree) and a
/// luminance (cd/m^2).
fn contrast_sensitivity(cycles_per_degree: f32, luminance: f32) -> f32 {
    let a = 440.0 * libm::powf(1.0 + 0.7 / luminance, -0.2);
    let b = 0.3 * libm::powf(1.0 + 100.0 / luminance, 0.15);
    a * cycles_per_degree
        * libm::expf(-b * cycles_per_degree)
        * libm::sqrtf(1.0 + 0.06 * libm::expf(b * cycles_per_degree))
}

/// Daly's visual masking (1993): how much contrast already present raises the threshold.
fn masking(contrast: f32) -> f32 {
    let a = libm::powf(392.498 * contrast, 0.7);
    let b = libm::powf(0.0153 * a, 4.0);
    libm::powf(1.0 + b, 0.25)
}

/// Display values to linear light.
fn linear([r, g, b]: [f32; 3]) -> [f32; 3] {
    let decode = |v: f32| libm::powf(v.clamp(0.0, 1.0), DISPLAY_GAMMA);
    [decode(r), decode(g), decode(b)]
}

/// Linear Adobe RGB (1998), white D65, to CIE XYZ.
fn xyz([r, g, b]: [f32; 3]) -> [f32; 3] {
    [
        r * 0.576_700 + g * 0.185_556 + b * 0.188_212,
        r * 0.297_361 + g * 0.627_355 + b * 0.075_284_7,
        r * 0.027_032_8 + g * 0.070_687_9 + b * 0.991_248,
    ]
}

/// CIE a* and b* of linear RGB, relative to the display's white.
fn chroma(rgb: [f32; 3]) -> [f32; 2] {
    let white = xyz([1.0, 1.0, 1.0]);
    let [x, y, z] = xyz(rgb);
    let f = |t: f32| {
        if t > 216.0 / 24389.0 {
            libm::cbrtf(t)
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(x / white[0]), f(y / white[1]), f(z / white[2]));
    [500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The squared chroma distance of two display colours (a*, b*; lightness is tested apart).
fn chroma_distance(a: [f32; 3], b: [f32; 3]) -> f32 {
    let ([a1, b1], [a2, b2]) = (chroma(linear(a)), chroma(linear(b)));
    (a1 - a2) * (a1 - a2) + (b1 - b2) * (b1 - b2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(width: usize, height: usize, v: f32) -> Vec<[f32; 3]> {
        vec![[v; 3]; width * height]
    }

    /// A deterministic noise in [-1, 1] per pixel and seed.
    fn noise(i: usize, seed: u32) -> f32 {
        let mut h = (i as u32).wrapping_mul(0x9E37_79B9) ^ seed.wrapping_mul(0x85EB_CA6B);
        h ^= h >> 15;
        h = h.wrapping_mul(0x2C1B_3C6D);
        h ^= h >> 12;
        (h as f32 / u32::MAX as f32) * 2.0 - 1.0
    }

    #[test]
    fn identical_images_do_not_differ() {
        let image = grey(40, 30, 0.5);
        assert_eq!(count_visible_differences(&image, &image, 40, 30), 0);
    }

    /// A mid-grey (about 22 cd/m^2 of display luminance) moved by 1 % is below the threshold of
    /// visibility (about 8 % there); moved by 30 % it is seen in every pixel.
    #[test]
    fn a_uniform_change_is_seen_only_above_the_threshold_of_visibility() {
        let (w, h) = (32, 32);
        let base = grey(w, h, 0.5);
        let luminance = xyz(linear([0.5; 3]))[1] * DISPLAY_LUMINANCE;
        let threshold = threshold_of_visibility(luminance) / luminance;
        assert!((0.05..0.1).contains(&threshold), "relative TVI {threshold}");
        let faint = grey(w, h, libm::powf(1.01, 1.0 / DISPLAY_GAMMA) * 0.5);
        assert_eq!(count_visible_differences(&base, &faint, w, h), 0);
        let strong = grey(w, h, libm::powf(1.3, 1.0 / DISPLAY_GAMMA) * 0.5);
        assert_eq!(
            count_visible_differences(&base, &strong, w, h),
            (w * h) as u64
        );
    }

    /// A change confined to a square is counted in the square, give or take the blur's reach.
    #[test]
    fn a_local_change_is_counted_where_it_is() {
        let (w, h) = (64, 48);
        let base = grey(w, h, 0.4);
        let mut changed = base.clone();
        for y in 10..20 {
            for x in 30..40 {
                changed[y * w + x] = [0.8, 0.4, 0.4];
            }
        }
        let failed = count_visible_differences(&base, &changed, w, h);
        assert!(
            (100..=196).contains(&failed),
            "{failed} pixels, the square has 100"
        );
    }

    /// Noise halving in amplitude between images: the share of pixels that change visibly
    /// falls with it, as a converging render's does.
    #[test]
    fn shrinking_noise_changes_fewer_pixels() {
        let (w, h) = (64, 64);
        let render = |amplitude: f32, seed: u32| -> Vec<[f32; 3]> {
            (0..w * h)
                .map(|i| [(0.5 + amplitude * noise(i, seed)).clamp(0.0, 1.0); 3])
                .collect()
        };
        let counts: Vec<u64> = [0.4f32, 0.2, 0.1, 0.005]
            .iter()
            .map(|&a| count_visible_differences(&render(a, 1), &render(a, 2), w, h))
            .collect();
        assert!(counts.windows(2).all(|c| c[0] >= c[1]), "{counts:?}");
        assert!(counts[0] > counts[2], "{counts:?}");
        assert!(counts[0] > (w * h / 10) as u64, "{counts:?}");
        assert_eq!(counts[3], 0, "{counts:?}");
    }

    /// A hue change of equal luminance is seen in a bright image, not in a dark one (colour is
    /// not compared in scotopic light).
    #[test]
    fn colour_is_compared_in_bright_regions_only() {
        let (w, h) = (16, 16);
        // Two colours of (almost) the same luminance: Y of red-ish vs green-ish.
        let warm = [0.9f32, 0.5, 0.5];
        let y_warm = xyz(linear(warm))[1];
        // A green of the same Y, found by bisection on its red and blue.
        let cool_of = |t: f32| [t, 0.9 * 0.75, t];
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if xyz(linear(cool_of(mid)))[1] < y_warm {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let cool = cool_of(lo);
        let bright = count_visible_differences(&vec![warm; w * h], &vec![cool; w * h], w, h);
        assert_eq!(bright, (w * h) as u64);
        let dim = |c: [f32; 3]| c.map(|v| v * 0.05);
        let dark =
            count_visible_differences(&vec![dim(warm); w * h], &vec![dim(cool); w * h], w, h);
        assert_eq!(dark, 0);
    }

    #[test]
    fn reflection_stays_inside() {
        assert_eq!(reflect(-2, 5), 2);
        assert_eq!(reflect(5, 5), 3);
        assert_eq!(reflect(6, 5), 2);
        assert_eq!(reflect(0, 1), 0);
        assert_eq!(reflect(-3, 2), 0);
    }
}
