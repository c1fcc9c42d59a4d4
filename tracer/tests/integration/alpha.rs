//! Alpha, LuxRender's coverage of the camera ray, filtered like the colour: a render whose Film
//! writes an alpha channel keeps it, 0 where the camera ray escapes to the sky (through null
//! surfaces and architectural panes, which it crosses straight on) and 1 where it meets
//! anything else (refracting glass included), whichever transport renders it.

use yat_tracer::assets::MemorySource;
use yat_tracer::film::Film;
use yat_tracer::integrator::Transport;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::RenderOverrides;

use crate::render::render_whole_with;

const SIDE: u32 = 32;

/// A 32x32 view along +z of a matte wall filling the half x <= 0 (the image's right half: the
/// camera's right is -x), the sky behind the rest; `filter` is the PixelFilter statement and
/// `extra` more world statements.
fn scene(filter: &str, extra: &str) -> String {
    format!(
        "Film \"fleximage\" \"integer xresolution\" [{SIDE}] \"integer yresolution\" [{SIDE}]\n\
         \x20 \"string write_png_channels\" [\"RGBA\"]\n\
         {filter}\n\
         LookAt 0 0 0  0 0 1  0 1 0\n\
         Camera \"perspective\" \"float fov\" [60]\n\
         WorldBegin\n\
         LightSource \"infinite\" \"color L\" [0.5 0.6 0.8]\n\
         Material \"matte\" \"color Kd\" [0.5 0.5 0.5]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [-100 -100 5  0 -100 5  0 100 5  -100 100 5]\n\
         {extra}\n\
         WorldEnd\n"
    )
}

fn render(text: &str, transport: Option<Transport>) -> Film {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.film.outputs.needs_alpha());
    let overrides = RenderOverrides {
        spp: Some(16),
        transport,
        ..Default::default()
    };
    render_whole_with(&desc, &source, &overrides)
}

fn alpha(film: &Film) -> Vec<f32> {
    film.alpha().expect("the film keeps alpha")
}

/// Under a box filter of half-width 0.5 each pixel's samples are its own: the wall's pixels
/// have alpha exactly 1, the sky's exactly 0, the mean exactly 0.5; every transport agrees.
#[test]
fn alpha_is_0_on_the_sky_and_1_on_the_wall() {
    let text = scene(
        "PixelFilter \"box\" \"float xwidth\" [0.5] \"float ywidth\" [0.5]",
        "",
    );
    for transport in [
        None,
        Some(Transport::Bidirectional),
        Some(Transport::DirectLighting),
    ] {
        let alpha = alpha(&render(&text, transport));
        for (i, &a) in alpha.iter().enumerate() {
            let x = i as u32 % SIDE;
            let expected = if x >= SIDE / 2 { 1.0 } else { 0.0 };
            assert_eq!(
                a,
                expected,
                "{transport:?}: pixel ({x}, {})",
                i as u32 / SIDE
            );
        }
        let mean = alpha.iter().sum::<f32>() / alpha.len() as f32;
        assert_eq!(mean, 0.5, "{transport:?}");
    }
}

/// Under LuxRender's default filter (mitchell, half-width 2) alpha is filtered as the colour
/// is: a weighted mean, exactly 0 or 1 beyond the filter's reach of the wall's edge, between
/// them (and, with the filter's negative lobes, a little beyond) next to it, 0.5 on average.
#[test]
fn alpha_is_filtered_like_the_colour() {
    let alpha = alpha(&render(&scene("", ""), None));
    for (i, &a) in alpha.iter().enumerate() {
        let x = (i as u32 % SIDE) as i32;
        match x - SIDE as i32 / 2 {
            d if d >= 2 => assert_eq!(a, 1.0, "pixel {i}"),
            d if d < -2 => assert_eq!(a, 0.0, "pixel {i}"),
            _ => assert!((-0.1..=1.1).contains(&a), "pixel {i}: {a}"),
        }
    }
    let mean = alpha.iter().sum::<f32>() / alpha.len() as f32;
    assert!((mean - 0.5).abs() < 0.01, "{mean}");
    // A row crosses the edge from 0 to 1.
    let row = &alpha[SIDE as usize * 10..SIDE as usize * 11];
    assert!(
        row[SIDE as usize / 2 - 1] < row[SIDE as usize / 2],
        "{row:?}"
    );
}

/// Camera rays cross null surfaces and architectural panes straight on, as LuxRender's do:
/// a null quad in front of the sky leaves it transparent, and a pane too but for the camera
/// rays it reflects (its Fresnel reflectance, about 4% head on: a reflection is a scattering
/// vertex); a glass sphere, which refracts the rays (a vertex too), is opaque.
#[test]
fn null_surfaces_and_panes_pass_through_refracting_glass_does_not() {
    // The sky's half is x > 0 in the world, columns 0..16; a null quad over its top rows, a
    // pane of architectural glass over its bottom rows, and a glass sphere between them.
    let extra = "AttributeBegin\n\
         Material \"null\"\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [0 1 3  4 1 3  4 4 3  0 4 3]\n\
         AttributeEnd\n\
         AttributeBegin\n\
         Material \"glass\" \"bool architectural\" [\"true\"]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [0 -4 3  4 -4 3  4 -1 3  0 -1 3]\n\
         AttributeEnd\n\
         AttributeBegin\n\
         Material \"glass\"\n\
         Translate 1.2 0 4\n\
         Shape \"sphere\" \"float radius\" [0.5]\n\
         AttributeEnd";
    let text = scene(
        "PixelFilter \"box\" \"float xwidth\" [0.5] \"float ywidth\" [0.5]",
        extra,
    );
    for transport in [None, Some(Transport::Bidirectional)] {
        let alpha = alpha(&render(&text, transport));
        let at = |x: u32, y: u32| alpha[(y * SIDE + x) as usize];
        // The null quad covers the top rows of the sky's half, the pane the bottom ones.
        assert_eq!(at(8, 3), 0.0, "{transport:?}: through the null quad");
        let pane: Vec<f32> = (27..SIDE)
            .flat_map(|y| (1..15).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .collect();
        let reflected = pane.iter().sum::<f32>() / pane.len() as f32;
        assert!(
            (0.015..0.09).contains(&reflected),
            "{transport:?}: through the pane, {reflected}"
        );
        // The glass sphere's centre, at x = 1.2 on z = 4: screen x = -1.2 / 4 / tan(30 deg).
        let column = (SIDE as f32 / 2.0
            * (1.0 - 1.2 / 4.0 / libm::tanf(std::f32::consts::FRAC_PI_6)))
            as u32;
        assert_eq!(at(column, SIDE / 2), 1.0, "{transport:?}: the glass sphere");
    }
}
