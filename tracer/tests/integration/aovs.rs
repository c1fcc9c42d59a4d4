//! The AOVs (`--aovs`, and the Film's `write_exr_ZBuf`): per pixel, the albedo, shading normal
//! and camera distance of the camera rays' first surface that is not `null`, filtered like the
//! colour, and the samples each pixel got; the same whichever transport renders them.

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::film::Film;
use yat_tracer::integrator::Transport;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::layers::Aovs;
use yat_tracer::render::RenderOverrides;

use crate::render::render_whole_with;

const SIDE: u32 = 32;
const SPP: u32 = 16;

/// A 32x32 view along +z of a matte wall (Kd 0.25 0.5 0.75) filling the half x <= 0 (the
/// image's right half) at z = 5, the sky behind the rest, and a null quad in front of the
/// wall's lower rows; a box filter of half-width 0.5, so each pixel's samples are its own.
fn scene(film: &str) -> String {
    format!(
        "Film \"fleximage\" \"integer xresolution\" [{SIDE}] \"integer yresolution\" [{SIDE}]\n\
         {film}\n\
         PixelFilter \"box\" \"float xwidth\" [0.5] \"float ywidth\" [0.5]\n\
         LookAt 0 0 0  0 0 1  0 1 0\n\
         Camera \"perspective\" \"float fov\" [60]\n\
         WorldBegin\n\
         LightSource \"infinite\" \"color L\" [0.5 0.6 0.8]\n\
         AttributeBegin\n\
         Material \"matte\" \"color Kd\" [0.25 0.5 0.75]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [-100 -100 5  0 -100 5  0 100 5  -100 100 5]\n\
         AttributeEnd\n\
         AttributeBegin\n\
         Material \"null\"\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [-4 -4 2  0 -4 2  0 -1 2  -4 -1 2]\n\
         AttributeEnd\n\
         WorldEnd\n"
    )
}

fn render(text: &str, aovs: Aovs, transport: Option<Transport>) -> Film {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    let overrides = RenderOverrides {
        spp: Some(SPP),
        transport,
        aovs,
        ..Default::default()
    };
    render_whole_with(&desc, &source, &overrides)
}

/// The wall's pixels: albedo exactly its Kd, normal exactly (0, 0, -1) (toward the camera),
/// depth the distance along each pixel's rays to z = 5 (through the null quad), samples
/// exactly 16; the sky's: albedo and normal 0, depth infinite; every transport alike.
#[test]
fn aovs_are_the_first_surfaces_albedo_normal_and_distance() {
    let all = Aovs::from_names("albedo,normal,depth,samples").unwrap();
    for transport in [None, Some(Transport::Bidirectional)] {
        let film = render(&scene(""), all, transport);
        let aovs = film.aovs();
        let (albedo, normal) = (aovs.albedo.unwrap(), aovs.normal.unwrap());
        let (depth, samples) = (aovs.depth.unwrap(), aovs.samples.unwrap());
        assert!(film.alpha().is_none(), "no file asks for alpha");
        for i in 0..(SIDE * SIDE) as usize {
            let (x, y) = (i as u32 % SIDE, i as u32 / SIDE);
            assert_eq!(samples[i], SPP as f32, "({x}, {y})");
            if x < SIDE / 2 {
                assert_eq!(
                    (albedo[i], normal[i], depth[i]),
                    (Vec3::ZERO, Vec3::ZERO, f32::INFINITY),
                    "{transport:?}: the sky at ({x}, {y})"
                );
                continue;
            }
            assert_eq!(albedo[i], Vec3::new(0.25, 0.5, 0.75), "({x}, {y})");
            assert_eq!(normal[i], Vec3::NEG_Z, "({x}, {y})");
            // The pixel centre's ray meets z = 5 at 5 / cos; its samples spread about it.
            let tan = libm::tanf(std::f32::consts::FRAC_PI_6);
            let sx = (1.0 - 2.0 * (x as f32 + 0.5) / SIDE as f32) * tan;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / SIDE as f32) * tan;
            let centre = 5.0 * libm::sqrtf(1.0 + sx * sx + sy * sy);
            assert!(
                (depth[i] - centre).abs() < 0.02 * centre,
                "{transport:?}: ({x}, {y}): {} for {centre}",
                depth[i]
            );
        }
    }
}

/// The Film's write_exr_ZBuf asks for depth alone, whatever --aovs says; a render asking for
/// nothing keeps no layer.
#[test]
fn write_exr_zbuf_keeps_depth() {
    let film = render(
        &scene("\"bool write_exr\" [\"true\"] \"bool write_exr_ZBuf\" [\"true\"]"),
        Aovs::NONE,
        None,
    );
    assert!(film.frame().layers.aovs.depth);
    let aovs = film.aovs();
    assert!(aovs.depth.is_some() && aovs.albedo.is_none() && aovs.samples.is_none());
    let plain = render(&scene(""), Aovs::NONE, None);
    assert!(plain.frame().layers.is_empty() && plain.aovs().is_empty());
}
