//! The parser's LuxRender conventions and defaults, on synthetic scenes held in memory.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat4, Vec3};
use yat_tracer::assets::MemorySource;
use yat_tracer::desc::*;
use yat_tracer::diag::Severity;
use yat_tracer::integrator::Transport;
use yat_tracer::lights::{DistantLight, InfiniteLight, PointLight, SpotLight};
use yat_tracer::material::glossy::CoatParams;
use yat_tracer::material::{self, Glass, Glossy, Matte, Metal, Mirror, Null};
use yat_tracer::math::luminance;
use yat_tracer::parse::{metal_preset, parse_scene};
use yat_tracer::render::{RenderOverrides, RenderSettings};
use yat_tracer::texture::{Checkerboard, Checkerboard3D, Constant, ImageMap, Mapping3D, Mix};

fn source(files: &[(&str, &[u8])]) -> MemorySource {
    let mut s = MemorySource::new();
    for (name, bytes) in files {
        s.insert(*name, Arc::from(*bytes));
    }
    s
}

fn parse(text: &str) -> SceneDesc {
    parse_with(text, &[])
}

fn parse_with(text: &str, files: &[(&str, &[u8])]) -> SceneDesc {
    let mut all = vec![("main.lxs", text.as_bytes())];
    all.extend_from_slice(files);
    parse_scene("main.lxs", &source(&all)).unwrap_or_else(|e| panic!("{e}"))
}

fn world(body: &str) -> SceneDesc {
    parse(&format!(
        "Camera \"perspective\"\nWorldBegin\n{body}\nWorldEnd\n"
    ))
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

fn png(width: u32, height: u32) -> Vec<u8> {
    let img = image::RgbImage::from_pixel(width, height, image::Rgb([200, 100, 50]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

#[test]
fn look_at_gives_luxrender_camera_basis() {
    let d = parse("LookAt 0 -5 0  0 0 0  0 0 1\nCamera \"perspective\"\nWorldBegin\nWorldEnd");
    let m = d.camera.camera_to_world;
    assert!(close(
        m.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, -5.0, 0.0)
    ));
    assert!(close(m.transform_vector3(Vec3::Z), Vec3::Y), "forward");
    assert!(close(m.transform_vector3(Vec3::X), Vec3::X), "right");
    assert!(close(m.transform_vector3(Vec3::Y), Vec3::Z), "up");
}

#[test]
fn camera_transform_is_the_one_current_at_camera_and_world_begin_resets_it() {
    let d = parse(
        "Translate 0 0 -3\nCamera \"perspective\"\nTranslate 100 0 0\nWorldBegin\nShape \"sphere\"\nWorldEnd",
    );
    // World-to-camera translates by -3 in z: the camera sits at z = +3.
    assert!(close(
        d.camera.camera_to_world.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 0.0, 3.0)
    ));
    assert_eq!(d.shapes[0].object_to_world, Mat4::IDENTITY);
}

#[test]
fn transform_is_column_major_and_transforms_post_multiply() {
    let d = world(
        "AttributeBegin\nTransform [0 1 0 0  -1 0 0 0  0 0 1 0  1 2 3 1]\nShape \"sphere\"\nAttributeEnd\n\
         AttributeBegin\nTranslate 1 0 0\nScale 2 2 2\nShape \"sphere\"\nAttributeEnd\n\
         AttributeBegin\nRotate 90 0 0 1\nConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 5 0 0 1]\nShape \"sphere\"\nAttributeEnd",
    );
    let m = d.shapes[0].object_to_world;
    assert!(
        close(m.transform_point3(Vec3::ZERO), Vec3::new(1.0, 2.0, 3.0)),
        "translation in 12-14"
    );
    assert!(
        close(m.transform_vector3(Vec3::X), Vec3::Y),
        "first column is the image of x"
    );
    let m = d.shapes[1].object_to_world;
    // current = translate x scale: scale applies to the object first.
    assert!(close(m.transform_point3(Vec3::X), Vec3::new(3.0, 0.0, 0.0)));
    let m = d.shapes[2].object_to_world;
    // Rotating +90 degrees about z (right-handed) takes the translated x axis to +y.
    assert!(close(
        m.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 5.0, 0.0)
    ));
}

#[test]
fn nested_attribute_blocks_restore_state() {
    let d = world(
        "Texture \"t\" \"color\" \"constant\" \"color value\" [0.1 0.2 0.3]\n\
         Material \"mirror\"\n\
         AttributeBegin\n\
           Translate 1 0 0\n ReverseOrientation\n Material \"null\"\n\
           Texture \"t\" \"color\" \"constant\" \"color value\" [0.9 0.9 0.9]\n\
           AreaLightSource \"area\" \"float power\" [0]\n\
           TransformBegin\n Translate 0 1 0\n Shape \"sphere\"\n TransformEnd\n\
           Shape \"sphere\"\n\
         AttributeEnd\n\
         Material \"matte\" \"texture Kd\" \"t\"\n\
         Shape \"sphere\"",
    );
    let [inner, middle, outer] = &d.shapes[..] else {
        panic!("3 shapes expected, got {}", d.shapes.len())
    };
    assert!(close(
        inner.object_to_world.transform_point3(Vec3::ZERO),
        Vec3::new(1.0, 1.0, 0.0)
    ));
    assert!(close(
        middle.object_to_world.transform_point3(Vec3::ZERO),
        Vec3::X
    ));
    assert!(inner.reverse_orientation && middle.reverse_orientation && inner.area_light.is_some());
    assert_eq!(
        d.materials[inner.material.0 as usize],
        MaterialDesc::Null(Null)
    );
    assert_eq!(outer.object_to_world, Mat4::IDENTITY);
    assert!(!outer.reverse_orientation && outer.area_light.is_none());
    // The texture defined inside the block went out of scope with it.
    let MaterialDesc::Matte(Matte {
        kd: ConstOrTexture::Texture(id),
        ..
    }) = d.materials[outer.material.0 as usize]
    else {
        panic!("matte with a texture expected")
    };
    assert_eq!(
        d.textures[id.0 as usize].kind,
        TextureKind::Constant(Constant {
            value: Vec3::new(0.1, 0.2, 0.3)
        })
    );
}

#[test]
fn default_screen_window_follows_the_aspect() {
    let wide = parse("Film \"fleximage\" \"integer xresolution\" [400] \"integer yresolution\" [200]\nCamera \"perspective\"\nWorldBegin\nWorldEnd");
    assert_eq!(wide.camera.screen_window, [-2.0, 2.0, -1.0, 1.0]);
    let tall = parse("Film \"fleximage\" \"integer xresolution\" [200] \"integer yresolution\" [400]\nCamera \"perspective\"\nWorldBegin\nWorldEnd");
    assert_eq!(tall.camera.screen_window, [-1.0, 1.0, -2.0, 2.0]);
    let given = parse(
        "Camera \"perspective\" \"float screenwindow\" [-1 1 -0.25 0.25]\nWorldBegin\nWorldEnd",
    );
    assert_eq!(given.camera.screen_window, [-1.0, 1.0, -0.25, 0.25]);
}

#[test]
fn options_have_luxrender_defaults() {
    let d = parse("Camera \"perspective\"\nWorldBegin\nWorldEnd");
    assert_eq!(d.camera.kind, CameraKind::Perspective { fov: 90.0 });
    assert_eq!((d.camera.lens_radius, d.camera.focal_distance), (0.0, 1e30));
    assert_eq!((d.camera.hither, d.camera.yon), (1e-3, 1e30));
    assert_eq!(
        (d.film.xresolution, d.film.yresolution, d.film.gamma),
        (800, 600, 2.2)
    );
    assert_eq!(d.film.tonemap, ToneMap::AutoLinear);
    assert_eq!(
        (d.film.filename.as_str(), d.film.haltspp, d.film.halttime),
        ("luxout", None, None)
    );
    assert_eq!(d.filter.kind, FilterKind::MITCHELL);
    assert_eq!((d.filter.xwidth, d.filter.ywidth), (2.0, 2.0));
    let i = &d.integrator;
    assert_eq!(
        (
            i.max_depth,
            i.rr_strategy,
            i.rr_continue_prob,
            i.include_environment
        ),
        (16, RussianRoulette::Efficiency, 0.65, true)
    );
    assert_eq!(d.sampler.pixel_samples, None);
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

#[test]
fn options_read_their_parameters() {
    let d = parse(
        "Film \"fleximage\" \"string tonemapkernel\" \"reinhard\" \"float reinhard_burn\" 3 \"integer haltspp\" 64 \"float halttime\" 30\n\
         PixelFilter \"gaussian\" \"float alpha\" 1.5 \"float xwidth\" 1\n\
         Sampler \"sobol\" \"integer pixelsamples\" [32]\n\
         SurfaceIntegrator \"path\" \"integer maxdepth\" 5 \"string rrstrategy\" \"none\" \"bool includeenvironment\" \"false\"\n\
         Camera \"fisheye\" \"float fov\" 55 \"float lensradius\" 0.1 \"float focaldistance\" 4\n\
         WorldBegin\nWorldEnd",
    );
    assert_eq!(
        d.film.tonemap,
        ToneMap::Reinhard {
            prescale: 1.0,
            postscale: 1.0,
            burn: 3.0
        }
    );
    assert_eq!((d.film.haltspp, d.film.halttime), (Some(64), Some(30.0)));
    assert_eq!(d.filter.kind, FilterKind::Gaussian { alpha: 1.5 });
    assert_eq!((d.filter.xwidth, d.filter.ywidth), (1.0, 2.0));
    assert_eq!(d.sampler.pixel_samples, Some(32));
    assert_eq!(
        (
            d.integrator.max_depth,
            d.integrator.rr_strategy,
            d.integrator.include_environment
        ),
        (5, RussianRoulette::None, false)
    );
    assert_eq!(d.camera.kind, CameraKind::Fisheye { fov: 55.0 });
    assert_eq!((d.camera.lens_radius, d.camera.focal_distance), (0.1, 4.0));
}

#[test]
fn bidirectional_renders_as_path_at_eyedepth_with_one_warning() {
    let d = parse("SurfaceIntegrator \"bidirectional\" \"integer eyedepth\" [8] \"integer lightdepth\" [8]\nWorldBegin\nWorldEnd");
    assert_eq!(
        (d.integrator.max_depth, d.integrator.requested.as_str()),
        (8, "bidirectional")
    );
    let w: Vec<_> = d
        .warnings
        .iter()
        .filter(|w| w.message.contains("bidirectional"))
        .collect();
    assert_eq!(w.len(), 1);
    assert_eq!(
        (w[0].pos.file.as_str(), w[0].pos.line, w[0].pos.column),
        ("main.lxs", 1, 1)
    );
}

#[test]
fn bidirectional_reads_luxrenders_depths_and_thresholds() {
    let d = parse(
        "SurfaceIntegrator \"bidirectional\" \"integer eyedepth\" [5] \"integer lightdepth\" [3] \
         \"float eyerrthreshold\" [0.25] \"float lightrrthreshold\" [0.5]\nWorldBegin\nWorldEnd",
    );
    let i = &d.integrator;
    assert_eq!(
        (
            i.max_depth,
            i.light_depth,
            i.eye_rr_threshold,
            i.light_rr_threshold
        ),
        (5, 3, 0.25, 0.5)
    );
    // LuxRender 1.x's defaults: 8 vertices a subpath, thresholds 0.
    let d = parse("SurfaceIntegrator \"bidirectional\"\nWorldBegin\nWorldEnd");
    let i = &d.integrator;
    assert_eq!(
        (
            i.max_depth,
            i.light_depth,
            i.eye_rr_threshold,
            i.light_rr_threshold
        ),
        (8, 8, 0.0, 0.0)
    );
}

/// LuxRender's direct lighting: its maxdepth counts the specular bounces after the first hit
/// (5 by default), the walk the vertices that take light (one more); no roulette; the scene's
/// transport unless the command line chooses another.
#[test]
fn directlighting_reads_luxrenders_depth_and_is_the_scenes_transport() {
    let d = parse("SurfaceIntegrator \"directlighting\"\nWorldBegin\nWorldEnd");
    let i = &d.integrator;
    assert_eq!(
        (i.max_depth, i.rr_strategy, d.transport()),
        (6, RussianRoulette::None, Transport::DirectLighting)
    );
    // The light strategy is listed as changing nothing in the image, and nothing else is said.
    let about_integrator = |d: &SceneDesc| {
        d.warnings.iter().any(|w| {
            w.severity != Severity::NoEffect
                && (w.message.contains("SurfaceIntegrator") || w.message.contains("strategy"))
        })
    };
    assert!(!about_integrator(&d), "{:?}", d.warnings);
    let d = parse(
        "SurfaceIntegrator \"directlighting\" \"integer maxdepth\" [2] \"string lightstrategy\" \"one\"\nWorldBegin\nWorldEnd",
    );
    assert_eq!(d.integrator.max_depth, 3);
    assert!(!about_integrator(&d), "{:?}", d.warnings);
    let resolve = |transport| {
        let overrides = RenderOverrides {
            transport,
            ..Default::default()
        };
        RenderSettings::resolve(&d, &overrides).transport
    };
    assert_eq!(resolve(None), Transport::DirectLighting);
    assert_eq!(resolve(Some(Transport::Path)), Transport::Path);
}

/// A scene's "bidirectional" renders bidirectional where path tracing would lose light (a
/// delta light and a mirror-like material: its caustics), with the path tracer elsewhere (the
/// same image sooner); "path" stays path tracing whatever the scene holds.
#[test]
fn bidirectional_is_the_transport_where_path_tracing_cannot_carry_the_caustics() {
    let transport = |integrator: &str, world: &str| {
        let d = parse(&format!(
            "SurfaceIntegrator \"{integrator}\"\nWorldBegin\n{world}\nWorldEnd"
        ));
        (d.transport(), d.delta_caustics())
    };
    let point = "LightSource \"point\" \"point from\" [0 0 2]\n";
    let area = "AttributeBegin\nAreaLightSource \"area\"\nShape \"sphere\"\nAttributeEnd\n";
    let glass = "Material \"glass\"\nShape \"sphere\"\n";
    let rough_metal = "Material \"metal\" \"float uroughness\" [0.1] \"float vroughness\" [0.1]\nShape \"sphere\"\n";
    let smooth_metal =
        "Material \"metal\" \"float uroughness\" [0] \"float vroughness\" [0]\nShape \"sphere\"\n";
    let spot = "LightSource \"spot\"\n";
    let mirror = "MakeNamedMaterial \"m\" \"string type\" \"mirror\"\nNamedMaterial \"m\"\nShape \"sphere\"\n";
    assert_eq!(
        transport("bidirectional", &format!("{point}{glass}")),
        (Transport::Bidirectional, Some(("point", "glass")))
    );
    assert_eq!(
        transport("bidirectional", &format!("{spot}{mirror}")),
        (Transport::Bidirectional, Some(("spot", "mirror")))
    );
    assert_eq!(
        transport("bidirectional", &format!("{point}{smooth_metal}")).0,
        Transport::Bidirectional
    );
    // A light sample finds the lamp through a rough lobe; an area light is found by BSDF
    // samples through glass: path tracing carries both.
    assert_eq!(
        transport("bidirectional", &format!("{point}{rough_metal}")),
        (Transport::Path, None)
    );
    assert_eq!(
        transport("bidirectional", &format!("{area}{glass}")),
        (Transport::Path, None)
    );
    assert_eq!(
        transport("path", &format!("{point}{glass}")),
        (Transport::Path, Some(("point", "glass")))
    );
}

#[test]
fn material_defaults_and_rules() {
    let d = world(
        "Material \"matte\"\nShape \"sphere\"\n\
         Material \"glossy\" \"float index\" [1.5] \"color Kd\" [2 0.5 -1]\nShape \"sphere\"\n\
         Material \"glossy\" \"float Ks\" [0.4]\nShape \"sphere\"\n\
         Material \"roughglass\"\nShape \"sphere\"\n\
         MakeNamedMaterial \"a\" \"string type\" \"mirror\"\nMakeNamedMaterial \"b\"\n\
         MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string namedmaterial1\" \"a\" \"string namedmaterial2\" \"b\" \"float amount\" 0.25\n\
         NamedMaterial \"m\"\nShape \"sphere\"\n\
         Shape \"sphere\"",
    );
    let mat = |i: usize| &d.materials[d.shapes[i].material.0 as usize];
    assert_eq!(
        *mat(0),
        MaterialDesc::Matte(Matte {
            kd: ConstOrTexture::color(Vec3::splat(0.9)),
            sigma: ConstOrTexture::float(0.0)
        })
    );
    let MaterialDesc::Glossy(Glossy {
        kd,
        coat:
            CoatParams {
                ks,
                ka,
                depth,
                uroughness,
                multibounce,
                ..
            },
    }) = mat(1)
    else {
        panic!()
    };
    assert_eq!(
        *kd,
        ConstOrTexture::color(Vec3::new(1.0, 0.5, 0.0)),
        "Kd clamped to [0, 1]"
    );
    let ConstOrTexture::Const(ks) = ks else {
        panic!()
    };
    assert!(
        close(*ks, Vec3::splat(0.04)),
        "Ks x ((1.5-1)/(1.5+1))^2: {ks}"
    );
    assert_eq!(
        (*ka, *depth, *uroughness, *multibounce),
        (
            ConstOrTexture::float(0.0),
            ConstOrTexture::float(0.0),
            ConstOrTexture::float(0.1),
            false
        )
    );
    let MaterialDesc::Glossy(Glossy {
        kd,
        coat: CoatParams { ks, .. },
    }) = mat(2)
    else {
        panic!()
    };
    assert_eq!(
        (*ks, *kd),
        (ConstOrTexture::float(0.4), ConstOrTexture::float(1.0)),
        "\"float Ks\" is a grey colour"
    );
    let MaterialDesc::Glass(Glass {
        kr,
        kt,
        index,
        architectural,
        uroughness,
        ..
    }) = mat(3)
    else {
        panic!()
    };
    assert_eq!(
        (*kr, *kt, *index, *architectural, *uroughness),
        (
            ConstOrTexture::float(1.0),
            ConstOrTexture::float(1.0),
            ConstOrTexture::float(1.5),
            false,
            ConstOrTexture::float(0.001)
        )
    );
    let MaterialDesc::Mix(material::Mix { a, b, amount }) = mat(4) else {
        panic!()
    };
    assert_eq!(
        d.materials[a.0 as usize],
        MaterialDesc::Mirror(Mirror {
            kr: ConstOrTexture::float(1.0),
            film: Default::default(),
        })
    );
    assert!(matches!(
        d.materials[b.0 as usize],
        MaterialDesc::Matte(Matte { .. })
    ));
    assert_eq!(*amount, ConstOrTexture::float(0.25));
    // NamedMaterial stays current for later shapes.
    assert_eq!(d.shapes[5].material, d.shapes[4].material);
}

#[test]
fn shape_without_material_is_default_matte() {
    let d = world("Shape \"sphere\"");
    assert_eq!(
        d.materials[d.shapes[0].material.0 as usize],
        MaterialDesc::Matte(Matte {
            kd: ConstOrTexture::color(Vec3::splat(0.9)),
            sigma: ConstOrTexture::float(0.0)
        })
    );
}

#[test]
fn metals_and_fresnel_textures() {
    let d = world(
        "Material \"metal\"\nShape \"sphere\"\n\
         Material \"metal\" \"string name\" \"gold\"\nShape \"sphere\"\n\
         Material \"metal\" \"string filename\" \"Au.nk\"\nShape \"sphere\"\n\
         Material \"metal2\"\nShape \"sphere\"\n\
         Material \"metal2\" \"float fresnel\" [2.5]\nShape \"sphere\"\n\
         Material \"metal2\" \"color fresnel\" [0.4 0.4 0.4]\nShape \"sphere\"\n\
         Material \"metal2\" \"color Kr\" [0.8 0.8 0.2]\nShape \"sphere\"\n\
         Texture \"fc\" \"color\" \"fresnelcolor\" \"color Kr\" [0.9 0.6 0.2]\n\
         Material \"metal2\" \"texture fresnel\" \"fc\"\nShape \"sphere\"\n\
         Texture \"fn\" \"fresnel\" \"fresnelname\" \"string name\" \"copper\"\n\
         Material \"metal2\" \"texture fresnel\" \"fn\"\nShape \"sphere\"",
    );
    let fresnel = |i: usize| match &d.materials[d.shapes[i].material.0 as usize] {
        MaterialDesc::Metal(Metal {
            fresnel,
            uroughness,
            ..
        }) => {
            assert_eq!(*uroughness, ConstOrTexture::float(0.1));
            fresnel.clone()
        }
        other => panic!("metal expected, got {other:?}"),
    };
    let conductor = |name| {
        let (eta, k) = metal_preset(name).unwrap();
        Fresnel::Conductor { eta, k }
    };
    assert_eq!(fresnel(0), conductor("aluminium"));
    assert_eq!(fresnel(1), conductor("gold"));
    assert_eq!(
        fresnel(2),
        conductor("aluminium"),
        ".nk files fall back to aluminium"
    );
    assert!(d.warnings.iter().any(|w| w.message.contains("Au.nk")));
    assert_eq!(fresnel(3), Fresnel::Index(ConstOrTexture::float(5.0)));
    assert_eq!(fresnel(4), Fresnel::Index(ConstOrTexture::float(2.5)));
    assert_eq!(fresnel(5), Fresnel::Reflectance(ConstOrTexture::float(0.4)));
    assert_eq!(
        fresnel(6),
        Fresnel::Reflectance(ConstOrTexture::color(Vec3::new(0.8, 0.8, 0.2)))
    );
    assert_eq!(
        fresnel(7),
        Fresnel::Reflectance(ConstOrTexture::color(Vec3::new(0.9, 0.6, 0.2)))
    );
    assert_eq!(fresnel(8), conductor("copper"));
    assert!(
        d.textures.is_empty(),
        "fresnel textures fold into the material"
    );
}

#[test]
fn textures_map_to_descriptions() {
    let img = png(4, 2);
    let d = parse_with(
        "Camera \"perspective\"\nWorldBegin\nTranslate 0 0 2\n\
         Texture \"im\" \"color\" \"imagemap\" \"string filename\" \"tex/a.png\" \"float gamma\" 2.2 \"string wrap\" \"clamp\" \"float vscale\" -1 \"float vdelta\" 1\n\
         Texture \"pl\" \"float\" \"imagemap\" \"string filename\" \"tex/a.png\" \"string mapping\" \"planar\" \"float uscale\" 3\n\
         Texture \"ck\" \"float\" \"checkerboard\" \"integer dimension\" 3 \"float tex2\" \"pl\"\n\
         Texture \"mx\" \"color\" \"mix\" \"texture tex1\" \"im\" \"float amount\" 0.3\n\
         Texture \"bb\" \"color\" \"blackbody\" \"float temperature\" 3000\n\
         Material \"matte\" \"texture Kd\" \"mx\" \"float sigma\" \"ck\"\nShape \"sphere\"\nWorldEnd",
        &[("tex/a.png", &img)],
    );
    let t = |n: usize| &d.textures[n].kind;
    let inv = Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0));
    assert_eq!(
        *t(0),
        TextureKind::ImageMap(ImageMap {
            filename: "tex/a.png".into(),
            gamma: 2.2,
            gain: 1.0,
            wrap: Wrap::Clamp,
            mapping: Mapping2D::Uv {
                uscale: 1.0,
                vscale: -1.0,
                udelta: 0.0,
                vdelta: 1.0
            },
        })
    );
    let TextureKind::ImageMap(ImageMap {
        mapping:
            Mapping2D::Planar {
                world_to_texture,
                v1,
                v2,
                ..
            },
        ..
    }) = t(1)
    else {
        panic!("{:?}", t(1))
    };
    assert!(world_to_texture.abs_diff_eq(inv, 1e-6) && *v1 == Vec3::X && *v2 == Vec3::Y);
    assert!(!d.textures[1].is_color && d.textures[0].is_color);
    assert_eq!(
        *t(2),
        TextureKind::Checkerboard(Checkerboard::D3(Checkerboard3D {
            tex1: ConstOrTexture::float(1.0),
            tex2: ConstOrTexture::Texture(TextureId(1)),
            // 3D mappings take the CTM uninverted, as LuxRender 1.x does.
            mapping: Mapping3D::global(Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0)))
        }))
    );
    assert_eq!(
        *t(3),
        TextureKind::Mix(Mix {
            tex1: ConstOrTexture::Texture(TextureId(0)),
            tex2: ConstOrTexture::float(1.0),
            amount: ConstOrTexture::float(0.3)
        })
    );
    let TextureKind::Constant(Constant { value: c }) = t(4) else {
        panic!()
    };
    assert!((luminance(*c) - 1.0).abs() < 1e-4 && c.x > c.z);
    assert_eq!(
        d.assets,
        vec![AssetRef {
            path: "tex/a.png".into(),
            kind: AssetKind::Image
        }],
        "one entry per file"
    );
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

#[test]
fn area_light_gain_uses_world_area_power_and_efficacy() {
    let d = world(
        "AttributeBegin\nScale 2 2 2\n\
         AreaLightSource \"area\" \"color L\" [1 0.5 0.25] \"float gain\" [3]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n\
         Shape \"sphere\" \"float radius\" 0.5\n\
         AttributeEnd\n\
         AttributeBegin\nAreaLightSource \"area\" \"color L\" [1 1 1] \"float power\" [0] \"float gain\" 5\nShape \"sphere\"\nAttributeEnd",
    );
    let l = Vec3::new(1.0, 0.5, 0.25);
    for (shape, area) in [(&d.shapes[0], 4.0), (&d.shapes[1], 4.0 * PI)] {
        let gain = 3.0 * 100.0 * 17.0 / (area * PI * luminance(l));
        let r = shape.area_light.as_ref().unwrap().radiance().unwrap();
        assert!(
            ((r - l * gain) / (l * gain)).abs().max_element() < 1e-4,
            "{r} vs {}",
            l * gain
        );
    }
    assert_eq!(
        d.shapes[2]
            .area_light
            .as_ref()
            .and_then(AreaLightDesc::radiance),
        Some(Vec3::splat(5.0))
    );
}

#[test]
fn lights_follow_luxrender_rules() {
    let d = world(
        "TransformBegin\nTranslate 1 2 3\n\
         LightSource \"point\" \"color L\" [1 1 1] \"float power\" [10] \"float efficacy\" [2] \"point from\" [0 0 1]\n\
         LightSource \"spot\" \"point from\" [0 0 0] \"point to\" [0 0 -1] \"float power\" 1 \"float efficacy\" 1\n\
         LightSource \"distant\" \"point from\" [0 0 1] \"point to\" [0 0 0] \"color L\" [2 2 2]\n\
         Scale -1 1 1\nLightSource \"infinite\" \"color L\" [0.5 0.5 0.5] \"float gain\" 2\n\
         TransformEnd\nLightSource \"sunsky\"\nLightSource \"sky\"",
    );
    let LightDesc::Point(PointLight {
        position,
        intensity,
    }) = &d.lights[0]
    else {
        panic!()
    };
    assert!(close(*position, Vec3::new(1.0, 2.0, 4.0)));
    assert!(close(*intensity, Vec3::splat(20.0 / (4.0 * PI))));
    let LightDesc::Spot(SpotLight {
        position,
        direction,
        intensity,
        cone_angle,
        cone_delta_angle,
    }) = &d.lights[1]
    else {
        panic!()
    };
    assert!(close(*position, Vec3::new(1.0, 2.0, 3.0)) && close(*direction, -Vec3::Z));
    assert_eq!((*cone_angle, *cone_delta_angle), (30.0, 5.0));
    let solid =
        2.0 * PI * (1.0 - 0.5 * (libm::cosf(25f32.to_radians()) + libm::cosf(30f32.to_radians())));
    assert!(close(*intensity, Vec3::splat(1.0 / solid)));
    let LightDesc::Distant(DistantLight { to_light, radiance }) = &d.lights[2] else {
        panic!()
    };
    assert!(close(*to_light, Vec3::Z) && *radiance == Vec3::splat(2.0));
    let LightDesc::Infinite(InfiniteLight {
        radiance,
        map,
        light_to_world,
    }) = &d.lights[3]
    else {
        panic!()
    };
    assert_eq!((*radiance, map.clone()), (Vec3::ONE, None));
    assert!(close(light_to_world.transform_vector3(Vec3::X), -Vec3::X));
    // sunsky is a sun and a sky; LuxRender's default sun points down and gives no light.
    let names: Vec<&str> = d.lights[4..].iter().map(|l| l.name()).collect();
    assert_eq!(names, ["sun", "sky", "sky"]);
    assert!(!d
        .warnings
        .iter()
        .any(|w| w.message.contains("not supported")));
    assert!(
        d.warnings
            .iter()
            .any(|w| w.message.contains("below the horizon")),
        "{:?}",
        d.warnings
    );
}

#[test]
fn object_instances_share_meshes_and_compose_transforms() {
    let d = world(
        "ObjectBegin \"tri\"\nTranslate 0 0 1\nShape \"trianglemesh\" \"point P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\nObjectEnd\n\
         AttributeBegin\nTranslate 5 0 0\nObjectInstance \"tri\"\nAttributeEnd\n\
         AttributeBegin\nTranslate -5 0 0\nObjectInstance \"tri\"\nAttributeEnd\nObjectInstance \"missing\"",
    );
    assert_eq!(d.shapes.len(), 2, "definitions are not shapes themselves");
    assert!(close(
        d.shapes[0].object_to_world.transform_point3(Vec3::ZERO),
        Vec3::new(5.0, 0.0, 1.0)
    ));
    assert!(close(
        d.shapes[1].object_to_world.transform_point3(Vec3::ZERO),
        Vec3::new(-5.0, 0.0, 1.0)
    ));
    let (Geometry::Mesh(a), Geometry::Mesh(b)) = (&d.shapes[0].geometry, &d.shapes[1].geometry)
    else {
        panic!()
    };
    assert!(Arc::ptr_eq(a, b));
    assert!(d.warnings.iter().any(|w| w.message.contains("\"missing\"")));
}

#[test]
fn meshes_quads_uvs_and_planes() {
    let d = world(
        "Shape \"mesh\" \"point P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"integer quadindices\" [0 1 2 3] \"float uv\" [0 0 1 0 1 1 0 1] \"normal N\" [0 0 1 0 0 1 0 0 1 0 0 1] \"string name\" \"quad\"\n\
         Shape \"plane\" \"normal n\" [0 0 2]\nShape \"plane\"",
    );
    let Geometry::Mesh(m) = &d.shapes[0].geometry else {
        panic!()
    };
    assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.uvs.as_ref().unwrap()[2], [1.0, 1.0]);
    assert_eq!(m.normals.as_ref().unwrap().len(), 4);
    assert_eq!(d.shapes[0].name, "quad");
    assert_eq!(
        d.shapes[1].geometry,
        Geometry::Plane(Plane { normal: Vec3::Z })
    );
    assert_eq!(
        d.shapes[2].geometry,
        Geometry::Plane(Plane { normal: Vec3::Z })
    );
}

#[test]
fn plymesh_is_read_through_the_source() {
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let d = parse_with(
        "WorldBegin\nShape \"plymesh\" \"string filename\" \"m/a.ply\"\nShape \"plymesh\" \"string filename\" \"m/a.ply\"\nWorldEnd",
        &[("m/a.ply", ply.as_bytes())],
    );
    let (Geometry::Mesh(a), Geometry::Mesh(b)) = (&d.shapes[0].geometry, &d.shapes[1].geometry)
    else {
        panic!()
    };
    assert_eq!(a.indices, vec![[0, 1, 2]]);
    assert!(Arc::ptr_eq(a, b), "one file, one mesh");
    assert_eq!(
        d.assets,
        vec![AssetRef {
            path: "m/a.ply".into(),
            kind: AssetKind::Ply
        }]
    );
}

#[test]
fn includes_are_relative_to_the_main_folder_and_listed_once() {
    let d = parse_with(
        "WorldBegin\nInclude \"sub/a.lxo\"\nInclude \"sub/b.lxo\"\nInclude \"sub/a.lxo\"\nWorldEnd",
        &[
            ("sub/a.lxo", b"Shape \"sphere\"\n"),
            ("sub/b.lxo", b"# paths stay relative to the main file\nInclude \"sub/a.lxo\"\nShape \"disk\" \"float bogus\" 1\n"),
        ],
    );
    assert_eq!(d.shapes.len(), 4);
    let paths: Vec<_> = d.assets.iter().map(|a| (a.path.as_str(), a.kind)).collect();
    assert_eq!(
        paths,
        vec![
            ("sub/a.lxo", AssetKind::Include),
            ("sub/b.lxo", AssetKind::Include)
        ]
    );
    let w = &d.warnings[0];
    assert_eq!(
        (w.pos.file.as_str(), w.pos.line, w.pos.column),
        ("sub/b.lxo", 3, 14),
        "{w}"
    );
}

#[test]
fn unknown_statements_and_parameters_warn_once_each() {
    let d = parse(
        "Frobnicate 1 2 \"x\"\nFrobnicate [3]\nCamera \"perspective\" \"float shutteropen\" 0 \"bool autofocus\" \"false\"\n\
         Film \"fleximage\" \"bool write_resume_flm\" \"true\" \"float colorspace_white\" [0.3 0.3] \"integer displayinterval\" 10\n\
         WorldBegin\nLightGroup \"default\"\nSearchPath \"textures\"\nAccelerator \"qbvh\"\n\
         Shape \"sphere\" \"float wobble\" 1 \"bool generatetangents\" \"false\" \"string name\" \"a\"\n\
         Shape \"sphere\" \"float wobble\" 2\nShape \"disk\" \"float wobble\" 2\nWorldEnd",
    );
    let of = |severity| -> Vec<String> {
        d.warnings
            .iter()
            .filter(|w| w.severity == severity)
            .map(|w| w.to_string())
            .collect()
    };
    // The differences: the unknown statement and parameters (a sphere's generatetangents too:
    // LuxRender reads it on meshes), each once with its count, and the film's colour space,
    // which is not LuxRender's default.
    let messages = of(Severity::Differs);
    assert_eq!(messages.len(), 5, "{messages:#?}");
    assert!(messages[0].starts_with("main.lxs:1:1:") && messages[0].contains("Frobnicate"));
    assert!(messages[1].contains("\"float colorspace_white\" [0.3 0.3] is not rendered"));
    assert!(messages[2].contains("Shape \"sphere\"") && messages[2].contains("float wobble"));
    assert!(messages[2].ends_with("(2 times)"));
    assert!(messages[3].contains("Shape \"sphere\"") && messages[3].contains("generatetangents"));
    assert!(messages[4].contains("Shape \"disk\""));
    // The exporter's output, display and shutter settings: listed as changing nothing (its
    // one light group, without settings, is rendered: no word of it).
    let quiet = of(Severity::NoEffect);
    assert_eq!(quiet.len(), 3, "{quiet:#?}");
    assert!(d
        .warnings
        .iter()
        .all(|w| !w.to_string().contains("LightGroup")));
    for name in ["write_resume_flm", "displayinterval", "shutteropen"] {
        assert!(quiet.iter().any(|m| m.contains(name)), "{name}: {quiet:#?}");
    }
    // SearchPath, which LuxRender's parser leaves unimplemented: a note.
    let notes = of(Severity::Note);
    assert!(
        notes
            .iter()
            .any(|m| m.starts_with("main.lxs:7:1: note: SearchPath")),
        "{notes:#?}"
    );
}

#[test]
fn motion_blocks_use_the_first_transform_with_one_warning() {
    let d = world(
        "AttributeBegin\nMotionBegin [0 1]\nTranslate 1 0 0\nTranslate 9 0 0\nMotionEnd\nShape \"sphere\"\nAttributeEnd\n\
         MotionBegin [0 1]\nTranslate 0 1 0\nTranslate 0 9 0\nMotionEnd\nShape \"sphere\"",
    );
    assert!(close(
        d.shapes[0].object_to_world.transform_point3(Vec3::ZERO),
        Vec3::X
    ));
    assert!(close(
        d.shapes[1].object_to_world.transform_point3(Vec3::ZERO),
        Vec3::Y
    ));
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
}

#[test]
fn coordinate_systems_are_named_and_restored() {
    let d = parse(
        "LookAt 0 -5 0 0 0 0 0 0 1\nCamera \"perspective\"\nWorldBegin\nTranslate 1 0 0\nCoordinateSystem \"mine\"\nIdentity\n\
         CoordSysTransform \"camera\"\nShape \"sphere\"\nCoordSysTransform \"mine\"\nShape \"sphere\"\nWorldEnd",
    );
    assert!(close(
        d.shapes[0].object_to_world.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, -5.0, 0.0)
    ));
    assert!(close(
        d.shapes[1].object_to_world.transform_point3(Vec3::ZERO),
        Vec3::X
    ));
}

#[test]
fn free_form_layout_and_optional_brackets() {
    let d = parse(
        "Film \"fleximage\"\n\"integer xresolution\"\n 320 \"integer yresolution\" [\n240\n] # comment [ ] \"\nCamera\n\"perspective\" \"float fov\" 30 WorldBegin Shape \"sphere\" \"float radius\" [ 2 ] WorldEnd",
    );
    assert_eq!((d.film.xresolution, d.film.yresolution), (320, 240));
    assert_eq!(d.camera.kind, CameraKind::Perspective { fov: 30.0 });
    assert!(
        matches!(d.shapes[0].geometry, Geometry::Sphere(Sphere { radius, zmin, zmax, phimax }) if (radius, zmin, zmax, phimax) == (2.0, -2.0, 2.0, 360.0))
    );
}

#[test]
fn empty_file_loads_defaults_with_warnings() {
    let d = parse("");
    assert!(d.shapes.is_empty() && d.lights.is_empty());
    assert_eq!((d.film.xresolution, d.film.yresolution), (800, 600));
    assert_eq!(d.camera.camera_to_world, Mat4::IDENTITY);
    assert!(d
        .warnings
        .iter()
        .any(|w| w.message.contains("no WorldBegin")));
    assert!(d.warnings.iter().any(|w| w.message.contains("no Camera")));
}

#[test]
fn unbalanced_blocks_are_warnings() {
    let d = world("AttributeEnd\nTransformBegin\nAttributeEnd\nAttributeBegin\nShape \"sphere\"");
    let m: Vec<_> = d.warnings.iter().map(|w| w.message.as_str()).collect();
    assert_eq!(m.len(), 3, "{m:?}");
    assert!(m[0].contains("AttributeEnd without a matching begin"));
    assert!(m[1].contains("closes the TransformBegin"));
    assert!(m[2].contains("AttributeBegin is never closed"));
    assert_eq!(d.shapes.len(), 1);
}

/// Accelerator, Renderer and VolumeIntegrator statements are read as the other option
/// statements are: their LuxRender parameters are listed as having no effect, an unknown one
/// is named as a difference, and a plugin LuxRender 1.x does not have is noted.
#[test]
fn accelerator_renderer_and_volume_integrator_parameters_are_judged() {
    let desc = parse(
        "Accelerator \"qbvh\" \"integer maxprimsperleaf\" [4] \"integer bogusA\" [1]\n\
         Renderer \"sampler\" \"bool bogusR\" [\"true\"]\n\
         VolumeIntegrator \"multi\" \"float stepsize\" [1] \"float bogusV\" [1]\n\
         Accelerator \"octree\"\n\
         WorldBegin\nWorldEnd\n",
    );
    let with = |severity: Severity, text: &str| {
        desc.warnings
            .iter()
            .any(|w| w.severity == severity && w.message.contains(text))
    };
    for bogus in ["bogusA", "bogusR", "bogusV"] {
        assert!(
            with(Severity::Differs, bogus),
            "{bogus}: {:?}",
            desc.warnings
        );
    }
    assert!(
        with(Severity::NoEffect, "maxprimsperleaf"),
        "{:?}",
        desc.warnings
    );
    assert!(with(Severity::NoEffect, "stepsize"), "{:?}", desc.warnings);
    assert!(
        with(
            Severity::Note,
            "Accelerator \"octree\" is not a LuxRender 1.x accelerator"
        ),
        "{:?}",
        desc.warnings
    );
}

/// A PortalShape belongs to the lights of the last LightSource of its attribute block, as
/// LuxRender's currentLight: kept for a sunsky (both its lights), with a "no effect" verdict;
/// ignored with a note after a point light or with no light in the block; placed by the
/// current transform.
#[test]
fn portal_shapes_follow_the_light_of_their_block() {
    let quad = "\"integer indices\" [0 1 2 0 2 3] \"point P\" [0 0 0 1 0 0 1 1 0 0 1 0]";
    let desc = world(&format!(
        "AttributeBegin\nLightSource \"sunsky\" \"vector sundir\" [0 0 1]\n\
         Translate 0 0 2\nPortalShape \"trianglemesh\" {quad}\nAttributeEnd\n\
         PortalShape \"trianglemesh\" {quad}\n\
         AttributeBegin\nLightSource \"point\"\nPortalShape \"trianglemesh\" {quad}\nAttributeEnd"
    ));
    assert_eq!(desc.portals.len(), 1, "{:?}", desc.warnings);
    let portal = &desc.portals[0];
    assert_eq!(portal.lights, 0..2);
    let triangles = portal.triangles();
    assert_eq!(triangles.len(), 2);
    assert!(triangles
        .iter()
        .all(|t| t.vertices.iter().all(|p| p.z == 2.0)));
    assert!(desc.shapes.is_empty(), "a portal is not a shape");
    let with = |severity: Severity, text: &str| {
        desc.warnings
            .iter()
            .any(|w| w.severity == severity && w.message.contains(text))
    };
    assert!(
        with(Severity::NoEffect, "PortalShape: light subpaths"),
        "{:?}",
        desc.warnings
    );
    assert!(
        with(Severity::Note, "no LightSource before it"),
        "{:?}",
        desc.warnings
    );
    assert!(
        with(Severity::Note, "point or spot light"),
        "{:?}",
        desc.warnings
    );
}
