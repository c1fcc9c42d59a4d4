//! Texture lookups against images generated here, with known texel values.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

use super::*;
use crate::assets::MemorySource;

const W: u32 = 4;
const H: u32 = 2;

/// Texel (x, y), y counted from the top row of the file: distinct 8-bit values.
fn texel_bytes(x: u32, y: u32) -> [u8; 3] {
    [
        (x * 60 + 10) as u8,
        (y * 200 + 20) as u8,
        (x * 20 + y * 100 + 5) as u8,
    ]
}

fn texel_linear(x: u32, y: u32, gamma: f32) -> Vec3 {
    let [r, g, b] = texel_bytes(x, y);
    Vec3::new(r as f32, g as f32, b as f32).map(|v| libm::powf(v / 255.0, gamma))
}

fn png() -> Arc<[u8]> {
    let img = ::image::RgbImage::from_fn(W, H, |x, y| ::image::Rgb(texel_bytes(x, y)));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, ::image::ImageFormat::Png).unwrap();
    bytes.into_inner().into()
}

fn source() -> MemorySource {
    let mut source = MemorySource::new();
    source.insert("tex/test.png", png());
    source
}

fn uv_identity() -> Mapping2D {
    Mapping2D::Uv {
        uscale: 1.0,
        vscale: 1.0,
        udelta: 0.0,
        vdelta: 0.0,
    }
}

fn imagemap(wrap: Wrap, gamma: f32, gain: f32, mapping: Mapping2D) -> TextureDesc {
    TextureDesc {
        name: "image".into(),
        is_color: true,
        kind: TextureKind::ImageMap(ImageMap {
            filename: "tex/test.png".into(),
            gamma,
            gain,
            wrap,
            mapping,
        }),
    }
}

fn at_uv(u: f32, v: f32) -> LookupPoint {
    LookupPoint::new(Vec3::ZERO, Vec2::new(u, v))
}

/// Texture coordinates of the centre of texel (x, y), which may lie outside the image.
fn centre(x: i32, y: i32) -> LookupPoint {
    at_uv((x as f32 + 0.5) / W as f32, (y as f32 + 0.5) / H as f32)
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn imagemap_returns_texels_at_their_centres_with_row_zero_on_top() {
    let textures = Textures::new(
        &[imagemap(Wrap::Repeat, 1.0, 1.0, uv_identity())],
        &source(),
    )
    .unwrap();
    let tex = ConstOrTexture::Texture(TextureId(0));
    for y in 0..H {
        for x in 0..W {
            let got = textures.eval(tex, &centre(x as i32, y as i32));
            assert!(
                close(got, texel_linear(x, y, 1.0)),
                "texel ({x},{y}): {got}"
            );
        }
    }
    // Halfway between two texel centres: their mean.
    let mid = textures.eval(tex, &at_uv(1.0 / W as f32, 0.25));
    assert!(
        close(
            mid,
            (texel_linear(0, 0, 1.0) + texel_linear(1, 0, 1.0)) * 0.5
        ),
        "{mid}"
    );
}

#[test]
fn blender_uv_convention_puts_v_zero_at_the_bottom_of_the_image() {
    let blender = Mapping2D::Uv {
        uscale: 1.0,
        vscale: -1.0,
        udelta: 0.0,
        vdelta: 1.0,
    };
    let textures = Textures::new(&[imagemap(Wrap::Clamp, 1.0, 1.0, blender)], &source()).unwrap();
    let bottom_left = textures.eval(ConstOrTexture::Texture(TextureId(0)), &at_uv(0.01, 0.01));
    assert!(
        close(bottom_left, texel_linear(0, H - 1, 1.0)),
        "{bottom_left}"
    );
}

#[test]
fn wrap_modes_outside_the_image() {
    let cases = [
        (
            Wrap::Repeat,
            texel_linear(W - 1, 1, 1.0),
            texel_linear(0, 0, 1.0),
        ),
        (
            Wrap::Clamp,
            texel_linear(0, 1, 1.0),
            texel_linear(W - 1, 0, 1.0),
        ),
        (Wrap::Black, Vec3::ZERO, Vec3::ZERO),
        (Wrap::White, Vec3::ONE, Vec3::ONE),
    ];
    for (wrap, left_of_row_1, right_of_row_0) in cases {
        let textures =
            Textures::new(&[imagemap(wrap, 1.0, 1.0, uv_identity())], &source()).unwrap();
        let tex = ConstOrTexture::Texture(TextureId(0));
        let left = textures.eval(tex, &centre(-1, 1));
        let right = textures.eval(tex, &centre(W as i32, 0));
        assert!(close(left, left_of_row_1), "{wrap:?} left: {left}");
        assert!(close(right, right_of_row_0), "{wrap:?} right: {right}");
        // Inside, every mode reads the image.
        assert!(close(
            textures.eval(tex, &centre(2, 1)),
            texel_linear(2, 1, 1.0)
        ));
    }
    // Repeat is periodic over whole images.
    let textures = Textures::new(
        &[imagemap(Wrap::Repeat, 1.0, 1.0, uv_identity())],
        &source(),
    )
    .unwrap();
    let far = textures.eval(
        ConstOrTexture::Texture(TextureId(0)),
        &at_uv(-3.0 + 2.5 / W as f32, 7.75),
    );
    assert!(close(far, texel_linear(2, 1, 1.0)), "{far}");
}

#[test]
fn gamma_gain_and_float_textures() {
    let mut float = imagemap(Wrap::Repeat, 2.2, 2.0, uv_identity());
    float.is_color = false;
    let descs = [imagemap(Wrap::Repeat, 2.2, 2.0, uv_identity()), float];
    let textures = Textures::new(&descs, &source()).unwrap();
    let expected = texel_linear(1, 0, 2.2) * 2.0;
    let color = textures.eval(ConstOrTexture::Texture(TextureId(0)), &centre(1, 0));
    assert!(close(color, expected), "{color} vs {expected}");
    let mean = textures.eval(ConstOrTexture::Texture(TextureId(1)), &centre(1, 0));
    assert!(
        close(mean, Vec3::splat(expected.element_sum() / 3.0)),
        "{mean}"
    );
    // Both name the same file with the same gamma: decoded once.
    assert_eq!(textures.images.len(), 1);
}

fn constant(name: &str, c: Vec3) -> TextureDesc {
    TextureDesc {
        name: name.into(),
        is_color: true,
        kind: TextureKind::Constant(Constant { value: c }),
    }
}

#[test]
fn checkerboards_alternate() {
    let descs = [
        TextureDesc {
            name: "check2d".into(),
            is_color: true,
            kind: TextureKind::Checkerboard(Checkerboard::D2(Checkerboard2D {
                tex1: ConstOrTexture::color(Vec3::ONE),
                tex2: ConstOrTexture::color(Vec3::ZERO),
                mapping: Mapping2D::Uv {
                    uscale: 4.0,
                    vscale: 4.0,
                    udelta: 0.0,
                    vdelta: 0.0,
                },
            })),
        },
        TextureDesc {
            name: "check3d".into(),
            is_color: true,
            kind: TextureKind::Checkerboard(Checkerboard::D3(Checkerboard3D {
                tex1: ConstOrTexture::color(Vec3::ONE),
                tex2: ConstOrTexture::color(Vec3::ZERO),
                mapping: Mapping3D::global(Mat4::from_scale(Vec3::splat(2.0))),
            })),
        },
    ];
    let textures = Textures::new(&descs, &MemorySource::new()).unwrap();
    for i in 0..8 {
        for j in 0..8 {
            let uv = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / 4.0 - Vec2::splat(1.0);
            let got = textures
                .eval(ConstOrTexture::Texture(TextureId(0)), &at_uv(uv.x, uv.y))
                .x;
            let expected = if (i + j) % 2 == 0 { 1.0 } else { 0.0 };
            assert_eq!(got, expected, "2D cell ({i},{j})");
        }
    }
    for (p, expected) in [
        (Vec3::new(0.25, 0.25, 0.25), 1.0),
        (Vec3::new(0.75, 0.25, 0.25), 0.0),
        (Vec3::new(0.75, 0.75, 0.25), 1.0),
        (Vec3::new(-0.25, 0.25, 0.25), 0.0),
        (Vec3::new(0.75, 0.75, 0.75), 0.0),
    ] {
        let got = textures
            .eval(
                ConstOrTexture::Texture(TextureId(1)),
                &LookupPoint::new(p, Vec2::ZERO),
            )
            .x;
        assert_eq!(got, expected, "3D at {p}");
    }
}

#[test]
fn scale_and_mix_combine_their_inputs() {
    let a = Vec3::new(0.2, 0.4, 0.6);
    let b = Vec3::new(1.0, 0.5, 0.0);
    let descs = [
        constant("a", a),
        constant("b", b),
        TextureDesc {
            name: "scale".into(),
            is_color: true,
            kind: TextureKind::Scale(Scale {
                tex1: ConstOrTexture::Texture(TextureId(0)),
                tex2: ConstOrTexture::Texture(TextureId(1)),
            }),
        },
        TextureDesc {
            name: "mix".into(),
            is_color: true,
            kind: TextureKind::Mix(Mix {
                tex1: ConstOrTexture::Texture(TextureId(0)),
                tex2: ConstOrTexture::Texture(TextureId(1)),
                amount: ConstOrTexture::float(0.25),
            }),
        },
    ];
    let textures = Textures::new(&descs, &MemorySource::new()).unwrap();
    let at = at_uv(0.0, 0.0);
    assert!(close(
        textures.eval(ConstOrTexture::Texture(TextureId(2)), &at),
        a * b
    ));
    assert!(close(
        textures.eval(ConstOrTexture::Texture(TextureId(3)), &at),
        a * 0.75 + b * 0.25
    ));
    // An id naming no texture is black rather than a panic.
    assert_eq!(
        textures.eval(ConstOrTexture::Texture(TextureId(99)), &at),
        Vec3::ZERO
    );
}

#[test]
fn bad_inputs_are_errors() {
    let missing = Textures::new(
        &[imagemap(Wrap::Repeat, 1.0, 1.0, uv_identity())],
        &MemorySource::new(),
    );
    let message = missing.err().expect("missing file is an error").to_string();
    assert!(message.contains("tex/test.png"), "{message}");

    let mut garbage = MemorySource::new();
    garbage.insert("tex/test.png", Arc::from(&b"not an image"[..]));
    let undecodable = Textures::new(&[imagemap(Wrap::Repeat, 1.0, 1.0, uv_identity())], &garbage);
    assert!(matches!(undecodable, Err(TextureError::Decode(_))));

    let forward = TextureDesc {
        name: "scale".into(),
        is_color: true,
        kind: TextureKind::Scale(Scale {
            tex1: ConstOrTexture::Texture(TextureId(0)),
            tex2: ConstOrTexture::float(1.0),
        }),
    };
    let err = Textures::new(&[forward], &MemorySource::new())
        .err()
        .expect("self reference");
    assert!(err.to_string().contains("\"scale\""), "{err}");
}
