//! Decoding the image files a scene references (textures, environment maps) into linear RGB.

use glam::Vec3;

/// A decoded image in linear RGB, rows top to bottom.
#[derive(Clone, Debug)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

impl RgbImage {
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
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
/// linear and are left alone.
pub fn decode(bytes: &[u8], path: &str, gamma: f32) -> Result<RgbImage, DecodeError> {
    let err = |source| DecodeError {
        path: path.to_string(),
        source,
    };
    let img = image::load_from_memory(bytes).map_err(err)?;
    let is_float = matches!(
        img.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let rgb = img.to_rgb32f();
    let (width, height) = rgb.dimensions();
    let linearise = |v: f32| {
        if is_float || gamma == 1.0 {
            v
        } else {
            v.max(0.0).powf(gamma)
        }
    };
    let pixels = rgb
        .pixels()
        .map(|p| Vec3::new(linearise(p[0]), linearise(p[1]), linearise(p[2])))
        .collect();
    Ok(RgbImage {
        width,
        height,
        pixels,
    })
}
