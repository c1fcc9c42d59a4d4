//! Decoding the image files a scene references (textures, environment maps) into linear RGB.

use glam::{Vec2, Vec3};

use crate::math::floor_to_int;

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
    tiling: Tiling,
    texels: Texels,
}

/// Texels are stored in 4x4 tiles (texels row-major inside a tile, tiles row-major), so that a
/// bilinear lookup's 2x2 footprint lies inside one tile 9 times in 16: with rows stored one
/// after another its two rows are always two cache lines apart, and an environment map looked
/// up at random directions misses the cache once per row. An 8-bit tile is one cache line.
const TILE: usize = 4;
const TILE_TEXELS: usize = TILE * TILE;

#[derive(Clone, Copy, Debug)]
struct Tiling {
    tiles_across: usize,
}

impl Tiling {
    fn new(width: u32) -> Self {
        Self {
            tiles_across: (width as usize).div_ceil(TILE),
        }
    }

    /// Tiles covering `height` rows.
    fn tiles(&self, height: u32) -> usize {
        self.tiles_across * (height as usize).div_ceil(TILE)
    }

    /// Where texel (x, y) is stored: (tile, texel within the tile).
    #[inline(always)]
    fn at(&self, x: usize, y: usize) -> (usize, usize) {
        (
            (y / TILE) * self.tiles_across + x / TILE,
            (y % TILE) * TILE + x % TILE,
        )
    }
}

/// 8-bit files of many colours keep their bytes and decode through a table: a quarter of the
/// memory of f32 texels (a fifth counting the padding byte, which makes an 8-bit tile one
/// 64-byte cache line), and an environment map looked up at random directions misses the
/// cache four times less often. The table gives the same values as decoding every texel up front.
///
/// 8-bit files of at most 256 colours (a checkerboard, a flat-shaded or posterised texture)
/// keep one byte per texel, an index into their colours: a quarter of `Bytes`' memory, so a
/// texture that indirect rays look up all over stays in the core's cache (a 400x400 floor of
/// two colours: 160 KiB instead of 640). Same values as `Bytes`. Indices packed into as few
/// bits as the colours need are no faster (bench/RESULTS.md, "Session 16").
#[derive(Clone, Debug)]
enum Texels {
    Linear(Vec<[Vec3; TILE_TEXELS]>),
    Bytes {
        tiles: Vec<ByteTile>,
        linear: Box<[f32; 256]>,
    },
    Indexed {
        tiles: Vec<[u8; TILE_TEXELS]>,
        palette: Box<[Vec3; 256]>,
    },
}

/// 16 texels of red, green, blue and a padding byte, aligned to a cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct ByteTile([[u8; 4]; TILE_TEXELS]);

impl RgbImage {
    /// `pixels` (`width` x `height` of them) in linear RGB, rows top to bottom.
    pub fn from_linear(width: u32, height: u32, pixels: Vec<Vec3>) -> Self {
        assert_eq!(
            pixels.len(),
            width as usize * height as usize,
            "{width} x {height} image given {} texels",
            pixels.len()
        );
        Self {
            width,
            height,
            tiling: Tiling::new(width),
            texels: Texels::Linear(tile(width, height, &pixels, Vec3::ZERO)),
        }
    }

    /// Texels counted: `width` x `height`.
    pub fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The texel at `index` in row-major order.
    pub fn texel(&self, index: usize) -> Vec3 {
        let w = self.width as usize;
        self.texel_at(index % w, index / w)
    }

    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.texel_at(x as usize, y as usize)
    }

    /// Texel (x, y), which must be inside the image.
    #[inline(always)]
    fn texel_at(&self, x: usize, y: usize) -> Vec3 {
        let (tile, i) = self.tiling.at(x, y);
        match &self.texels {
            Texels::Linear(tiles) => tiles[tile][i],
            Texels::Bytes { tiles, linear } => decode_code(linear, tiles[tile].0[i]),
            Texels::Indexed { tiles, palette } => palette[usize::from(tiles[tile][i])],
        }
    }

    /// Starts loading texel (x, y) into the cache (x86-64; nothing elsewhere), for a lookup
    /// near it whose coordinates wait on another cache miss. Only a hint: no result changes.
    #[inline(always)]
    pub fn prefetch(&self, x: usize, y: usize) {
        #[cfg(target_arch = "x86_64")]
        if x < self.width as usize && y < self.height as usize {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (tile, i) = self.tiling.at(x, y);
            let texel = match &self.texels {
                Texels::Linear(tiles) => tiles[tile][i..].as_ptr().cast::<i8>(),
                Texels::Bytes { tiles, .. } => tiles[tile].0[i..].as_ptr().cast::<i8>(),
                Texels::Indexed { tiles, .. } => tiles[tile][i..].as_ptr().cast::<i8>(),
            };
            // SAFETY: SSE is part of x86-64, and a prefetch reads nothing the program sees.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(texel) };
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (x, y);
    }

    /// Bilinear interpolation at `st` (0..1 across the image, texel centres at half-integer
    /// texel coordinates). Returns the weighted sum of the texels inside the image and the total
    /// weight that fell outside it under `Edge::Outside`, for the caller's border colour.
    pub fn bilinear(&self, st: Vec2, edge_s: Edge, edge_t: Edge) -> (Vec3, f32) {
        if self.is_empty() || !st.is_finite() {
            return (Vec3::ZERO, 0.0);
        }
        let xs = axis_neighbours(st.x, self.width, edge_s);
        let ys = axis_neighbours(st.y, self.height, edge_t);
        // Nearly every lookup's four texels exist after the edge rules (repeat and clamp always
        // find them; planar-mapped floors repeat far outside the first copy): those are read
        // directly, with the weights and sums in the order of the general case below (the same
        // bits), which then handles only the texels beyond an `Outside` edge.
        if let (([Some(x0), Some(x1)], fx), ([Some(y0), Some(y1)], fy)) = (xs, ys) {
            let mut inside = Vec3::ZERO;
            for (row, wy) in [(y0, 1.0 - fy), (y1, fy)] {
                inside += self.texel_at(x0, row) * ((1.0 - fx) * wy);
                inside += self.texel_at(x1, row) * (fx * wy);
            }
            return (inside, 0.0);
        }
        self.weigh_neighbours(xs, ys)
    }

    /// [`Self::bilinear`] of the texels the edge rules found along each axis (`None`: beyond
    /// an `Outside` edge, whose weight is the second value returned).
    fn weigh_neighbours(
        &self,
        (xs, fx): ([Option<usize>; 2], f32),
        (ys, fy): ([Option<usize>; 2], f32),
    ) -> (Vec3, f32) {
        let mut inside = Vec3::ZERO;
        let mut outside = 0.0;
        for (y, wy) in ys.into_iter().zip([1.0 - fy, fy]) {
            for (x, wx) in xs.into_iter().zip([1.0 - fx, fx]) {
                match (x, y) {
                    (Some(x), Some(y)) => inside += self.texel_at(x, y) * (wx * wy),
                    _ => outside += wx * wy,
                }
            }
        }
        (inside, outside)
    }

    /// Every texel, row-major.
    pub fn texels(&self) -> impl Iterator<Item = Vec3> + '_ {
        (0..self.height as usize)
            .flat_map(move |y| (0..self.width as usize).map(move |x| self.texel_at(x, y)))
    }
}

/// Row-major `texels` (`width` x `height` of them) in tiles, padded with `pad`.
fn tile<T: Copy>(width: u32, height: u32, texels: &[T], pad: T) -> Vec<[T; TILE_TEXELS]> {
    let tiling = Tiling::new(width);
    let mut tiles = vec![[pad; TILE_TEXELS]; tiling.tiles(height)];
    let w = width as usize;
    for (index, &v) in texels.iter().enumerate() {
        let (t, i) = tiling.at(index % w, index / w);
        tiles[t][i] = v;
    }
    tiles
}

/// Coordinate `c` (0..1 across an axis of `n` texels) in texels from the first texel's centre.
#[inline(always)]
fn axis_position(c: f32, n: u32) -> f32 {
    (c * n as f32 - 0.5).clamp(-MAX_COORD, MAX_COORD)
}

/// The two texels along one axis of length `n` that bracket coordinate `c` (0..1 across the
/// axis), after `edge`, and the weight of the second.
#[inline(always)]
fn axis_neighbours(c: f32, n: u32, edge: Edge) -> ([Option<usize>; 2], f32) {
    let x = axis_position(c, n);
    let i = floor_to_int(x);
    let (x0, n) = (i as f32, i64::from(n));
    let pair = match edge {
        Edge::Repeat => {
            // The division only for lookups outside the first copy, and in 32 bits, which
            // divide several times faster than 64: `i` is within +-MAX_COORD, and `n` below
            // 2^31 (an image that wide would hold over 2^31 texels, which no decode allocates;
            // past it the wrap would be wrong, not out of bounds: the remainder stays below n).
            let a = if (0..n).contains(&i) {
                i
            } else {
                i64::from((i as i32).rem_euclid(n as i32))
            };
            [a, if a + 1 == n { 0 } else { a + 1 }].map(Some)
        }
        Edge::Clamp => [i.clamp(0, n - 1), (i + 1).clamp(0, n - 1)].map(Some),
        Edge::Outside => [i, i + 1].map(|j| (0..n).contains(&j).then_some(j)),
    };
    (pair.map(|j| j.map(|j| j as usize)), x - x0)
}

/// An 8-bit texel's red, green and blue through the decoding table `linear`.
#[inline(always)]
fn decode_code(linear: &[f32; 256], [r, g, b, _]: [u8; 4]) -> Vec3 {
    Vec3::new(
        linear[usize::from(r)],
        linear[usize::from(g)],
        linear[usize::from(b)],
    )
}

/// The distinct colours of `codes` in order of first appearance and each code's index among
/// them, if there are at most 256; `None` as soon as a 257th appears.
fn palette_indices(codes: &[[u8; 4]]) -> Option<(Vec<[u8; 4]>, Vec<u8>)> {
    let mut index_of = std::collections::HashMap::with_capacity(256);
    let mut colours = Vec::with_capacity(256);
    let mut indices = Vec::with_capacity(codes.len());
    let mut previous = None;
    for &code in codes {
        let index = match previous {
            // Runs of one colour are common (flat areas): no hashing for them.
            Some((last, index)) if last == code => index,
            _ => match index_of.get(&code) {
                Some(&index) => index,
                None => {
                    let index = u8::try_from(colours.len()).ok()?;
                    index_of.insert(code, index);
                    colours.push(code);
                    index
                }
            },
        };
        previous = Some((code, index));
        indices.push(index);
    }
    Some((colours, indices))
}

/// What the decoder's own buffers and the allocator's rounding add while an image decodes, per
/// texel, rounded up (measured: docs/security.md, "build budget"). TGA, TIFF and BMP files
/// peak where PNG files of the same texels do (measured with a counting allocator on
/// 1024x1024 files: 15 bytes a texel for 8-bit RGB, 30 for 16-bit, 36 for float, all under
/// [`ImageCost::decode`]'s 16, 43 and 49): TIFF's decoder holds the texels in a buffer of its
/// own too, but frees it before the conversions that make the peak.
const DECODER_BYTES_PER_TEXEL: u64 = 1;

/// What an image takes in memory: the bytes its texels keep, and the most that making them
/// holds besides (the decoder's buffer and the conversions before the texels are tiled).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageCost {
    pub kept: u64,
    pub transient: u64,
}

impl ImageCost {
    /// What [`decode`] takes for a file of `width` x `height` texels of `color`, from its header.
    /// 8-bit files keep 4 bytes a texel (fewer when they have at most 256 colours, which only
    /// the decoding tells); while decoding, the decoder's buffer and the codes are held with
    /// the RGB copy the codes are made from, then with the tiles before they are aligned.
    /// Other files keep linear floats, made through an RGB float copy and the row-major texels.
    pub fn decode(width: u32, height: u32, color: image::ColorType) -> Self {
        let texels = u64::from(width) * u64::from(height);
        let tiled = Tiling::new(width).tiles(height) as u64 * TILE_TEXELS as u64;
        let buffer = texels * u64::from(color.bytes_per_pixel());
        if is_8_bit(color) {
            let code = std::mem::size_of::<[u8; 4]>() as u64;
            Self {
                kept: tiled * code,
                transient: buffer
                    + texels * (code + DECODER_BYTES_PER_TEXEL)
                    + (texels * 3).max(tiled * code),
            }
        } else {
            let linear = std::mem::size_of::<Vec3>() as u64;
            Self {
                kept: tiled * linear,
                transient: buffer + texels * (2 * linear + DECODER_BYTES_PER_TEXEL),
            }
        }
    }

    /// What [`RgbImage::from_linear`] takes for `width` x `height` texels: its tiles, and the
    /// row-major texels it is given.
    pub fn linear(width: u32, height: u32) -> Self {
        let texels = u64::from(width) * u64::from(height);
        let tiled = Tiling::new(width).tiles(height) as u64 * TILE_TEXELS as u64;
        let linear = std::mem::size_of::<Vec3>() as u64;
        Self {
            kept: tiled * linear,
            transient: texels * linear,
        }
    }
}

/// Whether [`decode`] keeps a file of `color` as 8-bit codes.
fn is_8_bit(color: image::ColorType) -> bool {
    matches!(
        color,
        image::ColorType::L8
            | image::ColorType::La8
            | image::ColorType::Rgb8
            | image::ColorType::Rgba8
    )
}

#[derive(Debug, thiserror::Error)]
#[error("cannot decode image \"{path}\": {source}")]
pub struct DecodeError {
    pub path: String,
    #[source]
    pub source: image::ImageError,
}

/// The format of the image file `bytes`, read from `path`: the one its first bytes announce,
/// else the one `path`'s extension names, in any case (exported scenes name files such as
/// `Material__1.JPG`).
///
/// The content is asked first because it cannot be wrong where it answers: a file's magic
/// number is what its decoder will read, while extensions are whatever an exporter or a user
/// named the file (a JPEG saved as `.png` decodes). TGA has no magic number, so it is found
/// only by the extension; and a real TGA header does not start like another format's
/// signature (its second byte, the colour-map type, is 0 or 1: of the signatures with a 0
/// there, ICO's would make it a colour-mapped TGA without a colour map, which is invalid, and
/// AVIF's would need `ftypavif` spelt in its origin fields), so the content does not take a
/// TGA for something else. A file whose content names a format is decoded as that,
/// and its decoder's error is the one reported: when that decoding fails, trying the
/// extension's decoder too would only hide the real error behind a second one.
pub fn format(bytes: &[u8], path: &str) -> image::ImageResult<image::ImageFormat> {
    image::guess_format(bytes).or_else(|unknown| {
        std::path::Path::new(path)
            .extension()
            .and_then(image::ImageFormat::from_extension)
            .ok_or(unknown)
    })
}

/// Decodes PNG, JPEG, TGA, TIFF, BMP, Radiance HDR or OpenEXR (the format found by
/// [`format`]). 8- and 16-bit formats are raised to the power `gamma` (LuxRender's imagemap
/// and infinite-light rule); floating-point formats (EXR, HDR, 32-bit float TIFF) are already
/// linear and are left alone, but for negative and non-finite values, which become 0 (they
/// are no radiance or reflectance, and one NaN texel would blacken whatever samples it).
pub fn decode(bytes: &[u8], path: &str, gamma: f32) -> Result<RgbImage, DecodeError> {
    let err = |source| DecodeError {
        path: path.to_string(),
        source,
    };
    let img = format(bytes, path)
        .and_then(|format| image::load_from_memory_with_format(bytes, format))
        .map_err(err)?;
    let linearise = |v: f32| {
        if gamma == 1.0 {
            v
        } else {
            libm::powf(v, gamma)
        }
    };
    let (width, height) = (img.width(), img.height());
    let texels = match img.color() {
        color if is_8_bit(color) => {
            let linear = Box::new(std::array::from_fn(|v| linearise(v as f32 / 255.0)));
            let codes: Vec<_> = img
                .to_rgb8()
                .pixels()
                .map(|p| [p[0], p[1], p[2], 0])
                .collect();
            match palette_indices(&codes) {
                Some((colours, indices)) => {
                    let mut palette = Box::new([Vec3::ZERO; 256]);
                    for (entry, &code) in palette.iter_mut().zip(&colours) {
                        *entry = decode_code(&linear, code);
                    }
                    Texels::Indexed {
                        tiles: tile(width, height, &indices, 0),
                        palette,
                    }
                }
                None => Texels::Bytes {
                    tiles: tile(width, height, &codes, [0; 4])
                        .into_iter()
                        .map(ByteTile)
                        .collect(),
                    linear,
                },
            }
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
            let pixels: Vec<_> = img
                .to_rgb32f()
                .pixels()
                .map(|p| Vec3::new(value(p[0]), value(p[1]), value(p[2])))
                .collect();
            Texels::Linear(tile(width, height, &pixels, Vec3::ZERO))
        }
    };
    Ok(RgbImage {
        width,
        height,
        tiling: Tiling::new(width),
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

    /// Lookups whose four texels exist after the edge rules take a shortcut: it gives the bits
    /// the general case gives, for every rule, on float, 8-bit and indexed texels, inside the
    /// image and in the repeats around it.
    #[test]
    fn shortcut_lookups_match_the_general_case_bit_for_bit() {
        let (w, h) = (23, 13);
        let float: Vec<Vec3> = (0..w * h)
            .map(|i| Vec3::new(i as f32 * 0.37, (i % 5) as f32, 1.0 / (1 + i) as f32))
            .collect();
        let png = |colour: fn(u32, u32) -> [u8; 3]| {
            let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(colour(x, y)));
            encode(image::DynamicImage::ImageRgb8(img), image::ImageFormat::Png)
        };
        // 299 colours (one per texel) and 7.
        let many = png(|x, y| [(x * 11) as u8, (y * 19) as u8, ((x * y) % 256) as u8]);
        let few = png(|x, y| [((x + y) % 7 * 30) as u8, 5, (x % 7 * 3) as u8]);
        let images = [
            RgbImage::from_linear(w, h, float),
            decode(&many, "many.png", 2.2).unwrap(),
            decode(&few, "few.png", 2.2).unwrap(),
        ];
        assert!(matches!(images[1].texels, Texels::Bytes { .. }));
        assert!(matches!(images[2].texels, Texels::Indexed { .. }));
        let edges = [Edge::Repeat, Edge::Clamp, Edge::Outside];
        let mut outside = 0;
        for image in &images {
            for k in 0..4000 {
                // A grid over [-2.1, 2.1)^2: the image, its edges and the copies around it.
                let st = Vec2::new((k % 61) as f32 / 14.5 - 2.1, (k / 61) as f32 / 15.6 - 2.1);
                for (s_edge, t_edge) in edges.iter().flat_map(|&s| edges.map(|t| (s, t))) {
                    let got = image.bilinear(st, s_edge, t_edge);
                    let general = image.weigh_neighbours(
                        axis_neighbours(st.x, w, s_edge),
                        axis_neighbours(st.y, h, t_edge),
                    );
                    outside += usize::from(general.1 > 0.0);
                    if (s_edge, t_edge) == (Edge::Repeat, Edge::Repeat) {
                        // The copies are the image again (up to rounding of the position).
                        let first_copy = image.bilinear(st.fract_gl(), s_edge, t_edge);
                        let scale = first_copy.0.max_element().max(1.0);
                        assert!(got.0.abs_diff_eq(first_copy.0, 1e-4 * scale), "{st}");
                    }
                    assert_eq!(
                        got.0.to_array().map(f32::to_bits),
                        general.0.to_array().map(f32::to_bits),
                        "{st}"
                    );
                    assert_eq!(got.1.to_bits(), general.1.to_bits(), "{st}");
                }
            }
        }
        // The general case's own work (weights beyond an `Outside` edge) was compared too.
        assert!(
            outside > 10_000,
            "only {outside} lookups reached beyond an edge"
        );
    }

    /// Texels are stored in 4x4 tiles: an image whose sides are not multiples of 4 still reads
    /// back in row-major order, and a lookup whose footprint spans four tiles weighs the four
    /// texels around it.
    #[test]
    fn tiled_texels_read_back_in_row_major_order() {
        let (w, h) = (9, 6);
        let pixels: Vec<Vec3> = (0..w * h)
            .map(|i| Vec3::new(i as f32, 0.5 * i as f32, 1.0))
            .collect();
        let image = RgbImage::from_linear(w, h, pixels.clone());
        assert_eq!(image.texels().collect::<Vec<_>>(), pixels);
        for (i, p) in pixels.iter().enumerate() {
            assert_eq!(image.texel(i), *p, "texel {i}");
        }
        // Halfway between the centres of texels 3 and 4 on both axes (tiles hold 0..=3, 4..=7).
        let got = image.bilinear(Vec2::new(4.0 / 9.0, 4.0 / 6.0), Edge::Clamp, Edge::Clamp);
        let want =
            (pixels[3 * 9 + 3] + pixels[3 * 9 + 4] + pixels[4 * 9 + 3] + pixels[4 * 9 + 4]) * 0.25;
        assert!(got.0.abs_diff_eq(want, 1e-4), "{got:?} against {want}");
    }

    /// 8-bit texels decode to their gamma curve, whether stored as bytes (more than 256
    /// colours) or as indices into their colours (256 at most).
    #[test]
    fn eight_bit_texels_decode_to_their_gamma_curve() {
        for (height, indexed) in [(16, true), (17, false)] {
            let img = image::RgbImage::from_fn(16, height, |x, y| {
                let v = (x * 16 + y) as u8;
                image::Rgb([v, 255 - v, if y < 16 { 7 } else { 9 }])
            });
            let bytes = encode(img.clone().into(), image::ImageFormat::Png);
            let decoded = decode(&bytes, "ramp.png", 2.2).unwrap();
            assert_eq!(
                (decoded.width, decoded.height, decoded.len()),
                (16, height, 16 * height as usize)
            );
            assert_eq!(
                matches!(decoded.texels, Texels::Indexed { .. }),
                indexed,
                "{height} rows"
            );
            for (x, y, p) in img.enumerate_pixels() {
                let want = Vec3::from_array(p.0.map(|v| libm::powf(f32::from(v) / 255.0, 2.2)));
                assert_eq!(decoded.get(x, y), want, "texel ({x}, {y})");
            }
        }
    }

    /// `img` as TGA, uncompressed or run-length encoded.
    fn tga(img: image::DynamicImage, rle: bool) -> Vec<u8> {
        use image::ImageEncoder;
        let mut bytes = Vec::new();
        let encoder = image::codecs::tga::TgaEncoder::new(&mut bytes);
        let encoder = if rle { encoder } else { encoder.disable_rle() };
        let (w, h) = (img.width(), img.height());
        encoder
            .write_image(img.as_bytes(), w, h, img.color().into())
            .unwrap();
        bytes
    }

    /// A `w` x `h` 8-bit picture of many colours with runs of one colour in every row (for the
    /// run-length encoders), different in every row and column, so that a flip or a transpose
    /// would show.
    fn picture(w: u32, h: u32) -> image::RgbImage {
        image::RgbImage::from_fn(w, h, |x, y| {
            let run = (x / 3) as u8;
            image::Rgb([
                run.wrapping_mul(40).wrapping_add(y as u8),
                250u8.wrapping_sub(17u8.wrapping_mul(y as u8)),
                (x * y) as u8 ^ 0x5a,
            ])
        })
    }

    /// `decoded` holds the 8-bit texels `want` raised to the power 2.2, exactly.
    fn assert_gamma_decoded(decoded: &RgbImage, want: &image::RgbImage, what: &str) {
        assert_eq!((decoded.width, decoded.height), want.dimensions(), "{what}");
        for (x, y, p) in want.enumerate_pixels() {
            let texel = Vec3::from_array(p.0.map(|v| libm::powf(f32::from(v) / 255.0, 2.2)));
            assert_eq!(decoded.get(x, y), texel, "{what}: texel ({x}, {y})");
        }
    }

    /// TGA has no magic number: its files are found by their extension (in any case), 8-bit
    /// RGB and RGBA (the alpha dropped), uncompressed and run-length encoded alike.
    #[test]
    fn tga_files_decode_by_their_extension_with_and_without_rle() {
        let rgb = picture(7, 5);
        let rgba = image::RgbaImage::from_fn(7, 5, |x, y| {
            let [r, g, b] = rgb.get_pixel(x, y).0;
            image::Rgba([r, g, b, (x * 30) as u8])
        });
        let images: [(&str, image::DynamicImage); 2] =
            [("rgb", rgb.clone().into()), ("rgba", rgba.into())];
        for (name, img) in images {
            for rle in [false, true] {
                let bytes = tga(img.clone(), rle);
                // Image type 2 is uncompressed true colour, 10 run-length encoded; 24 or 32 bits.
                assert_eq!(bytes[2], if rle { 10 } else { 2 }, "{name}");
                assert_eq!(bytes[16], if name == "rgb" { 24 } else { 32 }, "{name}");
                assert!(
                    image::guess_format(&bytes).is_err(),
                    "{name}: no magic number"
                );
                for path in ["maps/wood.tga", "maps/WOOD.TGA"] {
                    let decoded = decode(&bytes, path, 2.2).unwrap();
                    assert_gamma_decoded(&decoded, &rgb, &format!("{name}, rle {rle}, {path}"));
                }
                // Without the extension nothing names the format: an error naming the file.
                let err = decode(&bytes, "maps/wood", 2.2).unwrap_err();
                assert_eq!(err.path, "maps/wood");
                assert!(err.to_string().contains("\"maps/wood\""), "{err}");
            }
        }
        let runs = tga(rgb.clone().into(), true).len();
        let raw = tga(rgb.into(), false).len();
        assert!(runs < raw, "RLE {runs} bytes, uncompressed {raw}");
    }

    /// A run-length encoded TGA assembled by hand as Blender writes them (rows bottom to top,
    /// pixels blue-green-red, a run packet and raw packets) decodes the right way up.
    #[test]
    fn a_hand_made_bottom_up_rle_tga_decodes_the_right_way_up() {
        #[rustfmt::skip]
        let bytes = [
            // No id, no colour map, type 10 (RLE true colour), colour-map spec, origin (0, 0),
            // 3 x 2, 24 bits a pixel, descriptor 0 (no alpha, origin bottom left).
            0, 0, 10, 0, 0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 2, 0, 24, 0,
            // The bottom row: red twice (a run of 2), then green (a raw packet of 1).
            0x81, 0, 0, 255, 0x00, 0, 255, 0,
            // The top row: blue, white and (30, 20, 10) (a raw packet of 3).
            0x02, 255, 0, 0, 255, 255, 255, 10, 20, 30,
        ];
        let decoded = decode(&bytes, "blender.tga", 1.0).unwrap();
        let want = [
            [[0, 0, 255], [255, 255, 255], [30, 20, 10]],
            [[255, 0, 0], [255, 0, 0], [0, 255, 0]],
        ];
        assert_eq!((decoded.width, decoded.height), (3, 2));
        for (y, row) in want.iter().enumerate() {
            for (x, rgb) in row.iter().enumerate() {
                let texel = Vec3::from_array(rgb.map(|v: u8| f32::from(v) / 255.0));
                assert_eq!(decoded.get(x as u32, y as u32), texel, "texel ({x}, {y})");
            }
        }
    }

    /// Bytes that are no TGA, and a TGA cut short, are errors naming the file.
    #[test]
    fn a_broken_tga_is_an_error_naming_the_file() {
        let mut truncated = tga(picture(16, 16).into(), false);
        truncated.truncate(18 + 16 * 8 * 3);
        let garbage: [&[u8]; 4] = [
            b"",
            b"not a TGA",
            b"\x00\x07\x0b this is not a Targa file at all, nor any other image",
            &truncated,
        ];
        for bytes in garbage {
            let err = decode(bytes, "textures/broken.tga", 2.2).unwrap_err();
            assert_eq!(err.path, "textures/broken.tga");
            assert!(err.to_string().contains("\"textures/broken.tga\""), "{err}");
        }
    }

    /// 8-, 16- and 32-bit float TIFFs: 8 and 16 bits go through the gamma curve (16 bits as
    /// 16-bit PNGs do, to the bit), floats stay linear but for negative and NaN values.
    #[test]
    fn tiff_files_of_8_16_and_float_bits_decode_like_png_and_exr() {
        let rgb = picture(6, 4);
        let bytes = encode(rgb.clone().into(), image::ImageFormat::Tiff);
        assert_eq!(&bytes[..4], b"II*\0");
        // The content names the format: any extension, or none, reads it.
        for path in ["a.tif", "a.TIFF", "a.png", "a"] {
            assert_gamma_decoded(&decode(&bytes, path, 2.2).unwrap(), &rgb, path);
        }

        let deep = image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(5, 3, |x, y| {
            image::Rgb([(x * 13_000 + y) as u16, 65_535 - (y * 20_000) as u16, 7])
        });
        let tiff = encode(deep.clone().into(), image::ImageFormat::Tiff);
        let png = encode(deep.clone().into(), image::ImageFormat::Png);
        let (tiff, png) = (
            decode(&tiff, "deep.tif", 2.2).unwrap(),
            decode(&png, "deep.png", 2.2).unwrap(),
        );
        assert!(matches!(tiff.texels, Texels::Linear(_)));
        for (x, y, p) in deep.enumerate_pixels() {
            let want = Vec3::from_array(p.0.map(|v| libm::powf(f32::from(v) / 65_535.0, 2.2)));
            let got = tiff.get(x, y);
            assert!(
                got.abs_diff_eq(want, 1e-6),
                "({x}, {y}): {got} against {want}"
            );
            assert_eq!(got, png.get(x, y), "({x}, {y}) against the PNG");
        }
        // 13 000 / 65 535 ^ 2.2, not 13 000 / 65 535 (no gamma) nor 0 (the 8-bit branch).
        assert!(
            (tiff.get(1, 0).x - 0.028_473).abs() < 1e-5,
            "{}",
            tiff.get(1, 0)
        );

        let values = [
            0.25,
            3.5,
            -1.0,
            f32::NAN,
            f32::INFINITY,
            1e-3,
            0.5,
            12.0,
            0.0,
        ];
        let float = image::Rgb32FImage::from_fn(3, 1, |x, _| {
            let i = 3 * x as usize;
            image::Rgb([values[i], values[i + 1], values[i + 2]])
        });
        let bytes = encode(float.into(), image::ImageFormat::Tiff);
        let decoded = decode(&bytes, "float.tif", 2.2).unwrap();
        assert_eq!(decoded.get(0, 0), Vec3::new(0.25, 3.5, 0.0));
        assert_eq!(decoded.get(1, 0), Vec3::new(0.0, 0.0, 1e-3));
        assert_eq!(decoded.get(2, 0), Vec3::new(0.5, 12.0, 0.0));
    }

    /// 24-bit BMP (rows bottom to top, padded to 4 bytes: 5 texels of 3 bytes are 16 a row).
    #[test]
    fn bmp_files_of_24_bits_decode_to_their_gamma_curve() {
        let rgb = picture(5, 3);
        let bytes = encode(rgb.clone().into(), image::ImageFormat::Bmp);
        assert_eq!(&bytes[..2], b"BM");
        assert_eq!(
            u16::from_le_bytes([bytes[28], bytes[29]]),
            24,
            "bits a pixel"
        );
        for path in ["a.bmp", "A.BMP", "a"] {
            assert_gamma_decoded(&decode(&bytes, path, 2.2).unwrap(), &rgb, path);
        }
        // One texel by hand: (0, 0) is red 0, green 250, blue 0x5a.
        let want = Vec3::new(
            0.0,
            libm::powf(250.0 / 255.0, 2.2),
            libm::powf(90.0 / 255.0, 2.2),
        );
        assert_eq!(decode(&bytes, "a.bmp", 2.2).unwrap().get(0, 0), want);
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
