//! Decoding the image files a scene references (textures, environment maps) into linear RGB.

use glam::{Vec2, Vec3};

/// Texel coordinates beyond this are clamped before conversion to integers (far outside any
/// image, and small enough that neighbours never overflow).
const MAX_COORD: f32 = 1.0e9;

/// Where a texel coordinate beyond the image's edge reads from, along one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// The image tiles the plane.
    Repeat,
    /// The nearest edge texel.
    Clamp,
    /// Nothing: the weight of such texels is returned for the caller's border colour.
    Outside,
}

/// A decoded image in linear RGB, rows top to bottom.
#[derive(Clone, Debug)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    texels: Texels,
}

/// 8-bit files keep their bytes and decode through a table: a quarter of the memory of f32
/// texels, and an environment map looked up at random directions misses the cache four
/// times less often. The table gives the same values as decoding every texel up front.
#[derive(Clone, Debug)]
enum Texels {
    Linear(Vec<Vec3>),
    Bytes {
        codes: Vec<[u8; 3]>,
        linear: Box<[f32; 256]>,
    },
}

impl RgbImage {
    /// `pixels` in linear RGB, `width` x `height` of them, rows top to bottom.
    pub fn from_linear(width: u32, height: u32, pixels: Vec<Vec3>) -> Self {
        Self {
            width,
            height,
            texels: Texels::Linear(pixels),
        }
    }

    /// Texels counted, whatever `width` x `height` says.
    pub fn len(&self) -> usize {
        match &self.texels {
            Texels::Linear(pixels) => pixels.len(),
            Texels::Bytes { codes, .. } => codes.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The texel at `index` in row-major order.
    pub fn texel(&self, index: usize) -> Vec3 {
        match &self.texels {
            Texels::Linear(pixels) => pixels[index],
            Texels::Bytes { codes, linear } => {
                let [r, g, b] = codes[index];
                Vec3::new(
                    linear[usize::from(r)],
                    linear[usize::from(g)],
                    linear[usize::from(b)],
                )
            }
        }
    }

    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.texel((y * self.width + x) as usize)
    }

    /// Bilinear interpolation at `st` (0..1 across the image, texel centres at half-integer
    /// texel coordinates). Returns the weighted sum of the texels inside the image and the total
    /// weight that fell outside it under `Edge::Outside`, for the caller's border colour.
    pub fn bilinear(&self, st: Vec2, edge_s: Edge, edge_t: Edge) -> (Vec3, f32) {
        let (w, h) = (self.width as usize, self.height as usize);
        if w == 0 || h == 0 || self.len() < w * h || !st.is_finite() {
            return (Vec3::ZERO, 0.0);
        }
        let (xs, fx) = axis_neighbours(st.x, self.width, edge_s);
        let (ys, fy) = axis_neighbours(st.y, self.height, edge_t);
        let mut inside = Vec3::ZERO;
        let mut outside = 0.0;
        for (y, wy) in ys.into_iter().zip([1.0 - fy, fy]) {
            for (x, wx) in xs.into_iter().zip([1.0 - fx, fx]) {
                match (x, y) {
                    (Some(x), Some(y)) => inside += self.texel(y * w + x) * (wx * wy),
                    _ => outside += wx * wy,
                }
            }
        }
        (inside, outside)
    }

    /// Every texel, row-major.
    pub fn texels(&self) -> impl Iterator<Item = Vec3> + '_ {
        (0..self.len()).map(|i| self.texel(i))
    }
}

/// The two texels along one axis of length `n` that bracket coordinate `c` (0..1 across the
/// axis), after `edge`, and the weight of the second.
fn axis_neighbours(c: f32, n: u32, edge: Edge) -> ([Option<usize>; 2], f32) {
    let x = (c * n as f32 - 0.5).clamp(-MAX_COORD, MAX_COORD);
    let x0 = x.floor();
    let (i, n) = (x0 as i64, i64::from(n));
    let pair = match edge {
        Edge::Repeat => {
            // Lookups land inside the image nearly always: the division only when they do not.
            let a = if (0..n).contains(&i) {
                i
            } else {
                i.rem_euclid(n)
            };
            [a, if a + 1 == n { 0 } else { a + 1 }].map(Some)
        }
        Edge::Clamp => [i.clamp(0, n - 1), (i + 1).clamp(0, n - 1)].map(Some),
        Edge::Outside => [i, i + 1].map(|j| (0..n).contains(&j).then_some(j)),
    };
    (pair.map(|j| j.map(|j| j as usize)), x - x0)
}

#[derive(Debug, thiserror::Error)]
#[error("cannot decode image \"{path}\": {source}")]
pub struct DecodeError {
    pub path: String,
    #[source]
    pub source: image::ImageError,
}

/// Decodes PNG, JPEG, Radiance HDR or OpenEXR. 8- and 16-bit formats are raised to the power
/// `gamma` (LuxRender's imagemap and infinite-light rule); floating-point formats are already
/// linear and are left alone, but for negative and non-finite values, which become 0 (they
/// are no radiance or reflectance, and one NaN texel would blacken whatever samples it).
pub fn decode(bytes: &[u8], path: &str, gamma: f32) -> Result<RgbImage, DecodeError> {
    let err = |source| DecodeError {
        path: path.to_string(),
        source,
    };
    let img = image::load_from_memory(bytes).map_err(err)?;
    let linearise = |v: f32| {
        if gamma == 1.0 {
            v
        } else {
            v.powf(gamma)
        }
    };
    let (width, height) = (img.width(), img.height());
    let texels = match img.color() {
        image::ColorType::L8
        | image::ColorType::La8
        | image::ColorType::Rgb8
        | image::ColorType::Rgba8 => {
            let linear = Box::new(std::array::from_fn(|v| linearise(v as f32 / 255.0)));
            let codes = img.to_rgb8().pixels().map(|p| p.0).collect();
            Texels::Bytes { codes, linear }
        }
        color => {
            let is_float = matches!(color, image::ColorType::Rgb32F | image::ColorType::Rgba32F);
            let value = |v: f32| {
                if !v.is_finite() || v <= 0.0 {
                    0.0
                } else if is_float {
                    v
                } else {
                    linearise(v)
                }
            };
            let pixels = img
                .to_rgb32f()
                .pixels()
                .map(|p| Vec3::new(value(p[0]), value(p[1]), value(p[2])))
                .collect();
            Texels::Linear(pixels)
        }
    };
    Ok(RgbImage {
        width,
        height,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(img: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, format).unwrap();
        bytes.into_inner()
    }

    /// Halfway between the last texel of a row and the first, each edge rule reads what it
    /// says: both (repeat), the last twice (clamp), or the last and the border (outside).
    #[test]
    fn bilinear_across_the_edge_follows_the_edge_rule() {
        let row = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 4.0),
        ];
        let image = RgbImage::from_linear(3, 2, [row, row].concat());
        let at_right_edge = Vec2::new(1.0, 0.25);
        let cases = [
            (Edge::Repeat, Vec3::new(0.5, 0.0, 2.0), 0.0),
            (Edge::Clamp, Vec3::new(0.0, 0.0, 4.0), 0.0),
            (Edge::Outside, Vec3::new(0.0, 0.0, 2.0), 0.5),
        ];
        for (edge, inside, outside) in cases {
            let got = image.bilinear(at_right_edge, edge, Edge::Clamp);
            assert!(
                got.0.abs_diff_eq(inside, 1e-6) && (got.1 - outside).abs() < 1e-6,
                "{edge:?}: {got:?}"
            );
        }
        let third_of_the_way =
            image.bilinear(Vec2::new(1.0 / 3.0, 0.25), Edge::Repeat, Edge::Clamp);
        assert!(third_of_the_way
            .0
            .abs_diff_eq(Vec3::new(0.5, 0.0, 0.0), 1e-6));
        let nowhere = image.bilinear(Vec2::new(f32::NAN, 0.5), Edge::Repeat, Edge::Repeat);
        assert_eq!(nowhere, (Vec3::ZERO, 0.0));
    }

    #[test]
    fn eight_bit_texels_decode_to_their_gamma_curve() {
        let img = image::RgbImage::from_fn(16, 16, |x, y| {
            image::Rgb([(x * 16 + y) as u8, 255 - (x * 16 + y) as u8, 7])
        });
        let bytes = encode(img.clone().into(), image::ImageFormat::Png);
        let decoded = decode(&bytes, "ramp.png", 2.2).unwrap();
        assert_eq!(
            (decoded.width, decoded.height, decoded.len()),
            (16, 16, 256)
        );
        for (x, y, p) in img.enumerate_pixels() {
            let want = Vec3::from_array(p.0.map(|v| (f32::from(v) / 255.0).powf(2.2)));
            assert_eq!(decoded.get(x, y), want, "texel ({x}, {y})");
        }
    }

    #[test]
    fn float_texels_stay_linear_and_lose_negative_and_nan_values() {
        let values = [0.25, 3.5, -1.0, f32::NAN, f32::INFINITY, 1e-3];
        let img = image::Rgb32FImage::from_fn(2, 1, |x, _| {
            let i = 3 * x as usize;
            image::Rgb([values[i], values[i + 1], values[i + 2]])
        });
        let bytes = encode(img.into(), image::ImageFormat::OpenExr);
        let decoded = decode(&bytes, "hdr.exr", 2.2).unwrap();
        assert_eq!(decoded.get(0, 0), Vec3::new(0.25, 3.5, 0.0));
        assert_eq!(decoded.get(1, 0), Vec3::new(0.0, 0.0, 1e-3));
    }
}
