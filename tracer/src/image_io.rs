//! Decoding the image files a scene references (textures, environment maps) into linear RGB.

use glam::Vec3;

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

    /// Every texel, row-major.
    pub fn texels(&self) -> impl Iterator<Item = Vec3> + '_ {
        (0..self.len()).map(|i| self.texel(i))
    }
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
