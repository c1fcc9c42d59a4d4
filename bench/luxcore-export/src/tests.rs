//! The export's unit tests: small scenes parsed from text, their SDL and PLY checked.

use std::path::Path;

use glam::Vec3;
use yat_tracer::assets::MemorySource;
use yat_tracer::desc::SceneDesc;
use yat_tracer::mesh::ply::read_mesh;
use yat_tracer::parse::parse_scene;

use crate::{export, ExportOptions, LuxCoreScene};

fn parse(world: &str, camera: &str) -> SceneDesc {
    let text = format!(
        "LookAt 0 -5 1  0 0 1  0 0 1\n{camera}\n\
         Film \"fleximage\" \"integer xresolution\" [64] \"integer yresolution\" [32]\n\
         WorldBegin\n{world}\nWorldEnd\n"
    );
    let mut png = Vec::new();
    image::RgbImage::new(2, 2)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.into_bytes().into());
    source.insert("c.png", png.into());
    parse_scene("main.lxs", &source).expect("test scene parses")
}

fn export_world(world: &str) -> LuxCoreScene {
    export_world_with("", world)
}

/// `options` are statements before WorldBegin besides the camera and film.
fn export_world_with(options: &str, world: &str) -> LuxCoreScene {
    let camera = format!("Camera \"perspective\" \"float fov\" [40]\n{options}");
    let desc = parse(world, &camera);
    export(&desc, Path::new("/scenes"), &ExportOptions::default()).expect("exports")
}

/// The value of `key` in SDL text.
fn value<'a>(scn: &'a str, key: &str) -> &'a str {
    scn.lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(" = "))
        .unwrap_or_else(|| panic!("{key} missing from\n{scn}"))
}

fn floats(s: &str) -> Vec<f32> {
    s.split_whitespace().map(|x| x.parse().unwrap()).collect()
}

#[test]
fn camera_keeps_lookat_fov_and_screen_window() {
    let lux = export_world("");
    let scn = &lux.scene;
    assert_eq!(value(scn, "scene.camera.type"), "\"perspective\"");
    assert_eq!(
        floats(value(scn, "scene.camera.lookat.orig")),
        [0.0, -5.0, 1.0]
    );
    let target = floats(value(scn, "scene.camera.lookat.target"));
    assert!((target[1] + 4.0).abs() < 1e-5 && (target[2] - 1.0).abs() < 1e-5);
    assert_eq!(floats(value(scn, "scene.camera.fieldofview")), [40.0]);
    assert_eq!(
        floats(value(scn, "scene.camera.screenwindow")),
        [-2.0, 2.0, -1.0, 1.0]
    );
    assert_eq!(value(&lux.config, "film.width"), "64");
}

#[test]
fn fisheye_is_refused() {
    let desc = parse("", "Camera \"fisheye\" \"float fov\" [90]");
    let err = export(&desc, Path::new("."), &ExportOptions::default()).unwrap_err();
    assert!(err.to_string().contains("fisheye"), "{err}");
}

#[test]
fn null_emitter_is_clear_glass_that_neither_reflects_nor_bends_with_the_parsed_radiance() {
    let lux = export_world(
        "AttributeBegin\nMaterial \"null\"\n\
         AreaLightSource \"area\" \"color L\" [1 0.5 0.25] \"float gain\" [4] \"float power\" [0]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 2 1 0 2 0 1 2]\n\
         AttributeEnd",
    );
    let scn = &lux.scene;
    assert_eq!(value(scn, "scene.objects.object0.material"), "\"emitter0\"");
    // Not a black blocker (matte kd 0) and not LuxCore's pass-through null (which hides the
    // emission from every ray that reaches it): a hit that transmits everything straight on.
    assert_eq!(value(scn, "scene.materials.emitter0.type"), "\"glass\"");
    assert_eq!(floats(value(scn, "scene.materials.emitter0.kr")), [0.0; 3]);
    assert_eq!(floats(value(scn, "scene.materials.emitter0.kt")), [1.0; 3]);
    assert_eq!(
        floats(value(scn, "scene.materials.emitter0.interiorior")),
        [1.0]
    );
    assert_eq!(
        floats(value(scn, "scene.materials.emitter0.exteriorior")),
        [1.0]
    );
    assert!(!scn.contains("scene.materials.emitter0.kd"), "{scn}");
    assert_eq!(
        floats(value(scn, "scene.materials.emitter0.emission")),
        [4.0, 2.0, 1.0]
    );
}

#[test]
fn meshes_are_world_space_and_reverse_orientation_swaps_winding() {
    let shape = "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \
                 \"point P\" [0 0 0 1 0 0 0 1 0]";
    for (reverse, mirror) in [(false, false), (true, false), (false, true), (true, true)] {
        let lux = export_world(&format!(
            "AttributeBegin\nTranslate 1 2 3\n{}{}{shape}\nAttributeEnd",
            if reverse { "ReverseOrientation\n" } else { "" },
            if mirror { "Scale -1 1 1\n" } else { "" },
        ));
        let mesh = read_mesh(&lux.meshes[0].1).expect("our PLY reads back");
        let x = if mirror { -1.0 } else { 1.0 };
        assert_eq!(
            mesh.positions,
            [
                Vec3::new(1.0, 2.0, 3.0),
                Vec3::new(1.0 + x, 2.0, 3.0),
                Vec3::new(1.0, 3.0, 3.0)
            ]
        );
        let swapped = reverse ^ mirror;
        let expected = if swapped { [0, 2, 1] } else { [0, 1, 2] };
        assert_eq!(
            mesh.indices,
            [expected],
            "reverse {reverse} mirror {mirror}"
        );
    }
}

#[test]
fn planar_mapping_is_baked_into_vertex_uvs() {
    let lux = export_world(
        "Texture \"checks\" \"color\" \"imagemap\" \"string filename\" [\"c.png\"] \
         \"string mapping\" [\"planar\"] \"float udelta\" [0.5] \"float vdelta\" [0.25]\n\
         Material \"matte\" \"texture Kd\" [\"checks\"]\n\
         AttributeBegin\nTranslate 10 0 0\nScale 3 3 3\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0]\n\
         AttributeEnd",
    );
    let scn = &lux.scene;
    assert_eq!(value(scn, "scene.textures.tex0.file"), "\"/scenes/c.png\"");
    assert_eq!(
        floats(value(scn, "scene.textures.tex0.mapping.uvscale")),
        [1.0, 1.0]
    );
    assert_eq!(
        floats(value(scn, "scene.textures.tex0.mapping.uvdelta")),
        [0.0, 0.0]
    );
    // Planar mapping projects the object-space point: (0,0), (1,0), (0,1) plus delta.
    let mesh = read_mesh(&lux.meshes[0].1).unwrap();
    assert_eq!(mesh.uvs.unwrap(), [[0.5, 0.25], [1.5, 0.25], [0.5, 1.25]]);
}

#[test]
fn uv_mapping_parameters_carry_over_and_metal2_gets_a_fresnel_texture() {
    let lux = export_world(
        "Texture \"t\" \"color\" \"imagemap\" \"string filename\" [\"c.png\"] \
         \"float vscale\" [-1] \"float vdelta\" [1]\n\
         Material \"metal2\" \"color fresnel\" [0.4 0.4 0.4] \"float uroughness\" [0.1] \
         \"float vroughness\" [0.1]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0]",
    );
    let scn = &lux.scene;
    assert_eq!(
        floats(value(scn, "scene.textures.tex0.mapping.uvscale")),
        [1.0, -1.0]
    );
    assert_eq!(
        floats(value(scn, "scene.textures.tex0.mapping.uvdelta")),
        [0.0, 1.0]
    );
    let m = value(scn, "scene.objects.object0.material").trim_matches('"');
    assert_eq!(
        value(scn, &format!("scene.materials.{m}.type")),
        "\"metal2\""
    );
    let fresnel = value(scn, &format!("scene.materials.{m}.fresnel")).trim_matches('"');
    let fresnel = format!("scene.textures.{fresnel}");
    assert_eq!(value(scn, &format!("{fresnel}.type")), "\"fresnelcolor\"");
    assert_eq!(floats(value(scn, &format!("{fresnel}.kr"))), [0.4; 3]);
}

#[test]
fn luxrender_extras_map_to_luxcore_materials() {
    let lux = export_world(
        "Material \"carpaint\" \"string name\" \"blue\"\nShape \"sphere\"\n\
         Material \"velvet\" \"float p2\" [10]\nShape \"sphere\"\n\
         MakeNamedMaterial \"base\" \"string type\" \"matte\"\n\
         MakeNamedMaterial \"c\" \"string type\" \"glossycoating\" \"string basematerial\" \"base\" \"float uroughness\" [0.3]\n\
         NamedMaterial \"c\"\nShape \"sphere\"\n\
         Material \"glossytranslucent\" \"bool onesided\" \"false\" \"color backface_Ks\" [0.2 0.2 0.2]\nShape \"sphere\"\n\
         Texture \"lamp\" \"color\" \"lampspectrum\" \"string name\" \"LPS\"\n\
         Material \"cloth\" \"string presetname\" \"silk_shantung\" \"texture warp_Kd\" \"lamp\" \"color weft_Ks\" [0.1 0.2 0.3] \"float repeat_u\" [40]\nShape \"sphere\"",
    );
    let scn = &lux.scene;
    let key = |m: &str, k: &str| value(scn, &format!("scene.materials.{m}.{k}")).to_string();
    let types: Vec<String> = scn
        .lines()
        .filter(|l| l.starts_with("scene.materials.") && l.contains(".type = "))
        .map(|l| l.split(" = ").nth(1).unwrap().trim_matches('"').to_string())
        .collect();
    for t in [
        "carpaint",
        "velvet",
        "glossycoating",
        "glossytranslucent",
        "cloth",
        "matte",
    ] {
        assert!(types.iter().any(|x| x == t), "{t} missing from {types:?}");
    }
    let find = |ty: &str| {
        scn.lines()
            .find_map(|l| {
                let rest = l.strip_prefix("scene.materials.")?;
                let (name, v) = rest.split_once(".type = ")?;
                (v.trim_matches('"') == ty).then(|| name.to_string())
            })
            .unwrap()
    };
    let paint = find("carpaint");
    // The blue preset's base colour and third lobe.
    assert_eq!(floats(&key(&paint, "kd")), [0.0079, 0.023, 0.1]);
    assert_eq!(floats(&key(&paint, "m3")), [0.02]);
    let velvet = find("velvet");
    assert_eq!(floats(&key(&velvet, "p2")), [10.0]);
    assert_eq!(floats(&key(&velvet, "thickness")), [0.1]);
    let coating = find("glossycoating");
    let base = key(&coating, "base");
    assert_eq!(key(base.trim_matches('"'), "type"), "\"matte\"");
    assert_eq!(floats(&key(&coating, "uroughness")), [0.3]);
    let leaf = find("glossytranslucent");
    assert_eq!(floats(&key(&leaf, "ks_bf")), [0.2; 3]);
    assert_eq!(floats(&key(&leaf, "uroughness_bf")), [0.0]);
    let cloth = find("cloth");
    assert_eq!(key(&cloth, "preset"), "\"silk_shantung\"");
    assert_eq!(floats(&key(&cloth, "weft_ks")), [0.1, 0.2, 0.3]);
    assert_eq!(floats(&key(&cloth, "weft_kd")), [0.0; 3]);
    assert_eq!(floats(&key(&cloth, "repeat_u")), [40.0]);
    assert_eq!(floats(&key(&cloth, "repeat_v")), [100.0]);
    // The lamp's spectrum went out as a constant texture of its (orange) colour.
    let lamp = format!(
        "scene.textures.{}",
        key(&cloth, "warp_kd").trim_matches('"')
    );
    assert_eq!(value(scn, &format!("{lamp}.type")), "\"constfloat3\"");
    let warp = floats(value(scn, &format!("{lamp}.value")));
    assert!(warp[0] > 3.0 * warp[1] && warp[1] > warp[2], "{warp:?}");
}

#[test]
fn sun_and_sky_become_luxcores_sun_and_sky2() {
    let lux = export_world(
        "AttributeBegin\nRotate 90 0 0 1\n\
         LightSource \"sunsky2\" \"vector sundir\" [0 0.6 0.8] \"float turbidity\" [3] \"float relsize\" [2] \"float gain\" [0.5]\n\
         AttributeEnd\nLightSource \"sky\" \"vector sundir\" [0 0 1]",
    );
    let scn = &lux.scene;
    assert_eq!(value(scn, "scene.lights.light0.type"), "\"sun\"");
    // The sun's direction is in world space (turned by the Rotate); the sky's stays in light
    // space with the transformation beside it.
    let dir = floats(value(scn, "scene.lights.light0.dir"));
    assert!((dir[0] + 0.6).abs() < 1e-5 && dir[1].abs() < 1e-5 && (dir[2] - 0.8).abs() < 1e-5);
    assert_eq!(floats(value(scn, "scene.lights.light0.turbidity")), [3.0]);
    assert_eq!(floats(value(scn, "scene.lights.light0.relsize")), [2.0]);
    assert_eq!(floats(value(scn, "scene.lights.light0.gain")), [0.5; 3]);
    assert_eq!(value(scn, "scene.lights.light1.type"), "\"sky2\"");
    assert_eq!(
        floats(value(scn, "scene.lights.light1.dir")),
        [0.0, 0.6, 0.8]
    );
    let m = floats(value(scn, "scene.lights.light1.transformation"));
    assert!(
        (m[1] - 1.0).abs() < 1e-5 && (m[4] + 1.0).abs() < 1e-5,
        "{m:?}"
    );
    assert_eq!(floats(value(scn, "scene.lights.light1.gain")), [0.5; 3]);
    // A Preetham sky has no LuxCore equivalent: sky2, with a note.
    assert_eq!(value(scn, "scene.lights.light2.type"), "\"sky2\"");
    assert!(
        lux.notes.iter().any(|n| n.contains("Preetham")),
        "{:?}",
        lux.notes
    );
}

/// Clear and homogeneous volumes become LuxCore's, the camera's volume is set, and a shape
/// with volumes gets its own copy of its material carrying them (a shape without keeps the
/// shared material). The scene asks for the "multi" volume integrator, so the smoke scatters.
#[test]
fn volumes_map_to_luxcore_volumes() {
    let scene = export_world_with(
        "VolumeIntegrator \"multi\"",
        r#"MakeNamedVolume "air" "clear" "float fresnel" [1.0002926]
MakeNamedVolume "ink" "clear" "float fresnel" [1.2] "color absorption" [0.5 1 2]
MakeNamedVolume "smoke" "homogeneous" "color sigma_a" [0.1 0.2 0.3] "color sigma_s" [2 2 2] "float g" [0.4]
Exterior "air"
Material "glass2"
AttributeBegin
  Interior "ink"
  Shape "sphere" "float radius" [1]
AttributeEnd
Material "null"
Interior "smoke"
Shape "sphere" "float radius" [0.5]
AttributeBegin
  Interior ""
  Exterior ""
  Shape "sphere" "float radius" [0.25]
AttributeEnd"#,
    );
    let scn = &scene.scene;
    assert_eq!(value(scn, "scene.volumes.vol0.type"), "\"clear\"");
    let air_ior: f32 = value(scn, "scene.volumes.vol0.ior").parse().unwrap();
    assert_eq!(air_ior, 1.000_292_6);
    assert_eq!(value(scn, "scene.volumes.vol1.absorption"), "0.5 1 2");
    assert_eq!(value(scn, "scene.volumes.vol2.type"), "\"homogeneous\"");
    assert_eq!(value(scn, "scene.volumes.vol2.scattering"), "2 2 2");
    assert_eq!(value(scn, "scene.volumes.vol2.asymmetry"), "0.4 0.4 0.4");
    assert_eq!(value(scn, "scene.volumes.vol2.multiscattering"), "1");
    assert_eq!(value(scn, "scene.camera.volume"), "\"vol0\"");
    let material = value(scn, "scene.objects.object0.material").trim_matches('"');
    assert_eq!(
        value(scn, &format!("scene.materials.{material}.volume.interior")),
        "\"vol1\""
    );
    assert_eq!(
        value(scn, &format!("scene.materials.{material}.volume.exterior")),
        "\"vol0\""
    );
    // glass2's index is the interior's over the exterior's.
    let ior: f32 = value(scn, &format!("scene.materials.{material}.interiorior"))
        .parse()
        .unwrap();
    assert!((ior - 1.2 / 1.000_292_6).abs() < 1e-6, "{ior}");
    let smoke = value(scn, "scene.objects.object1.material").trim_matches('"');
    assert_eq!(
        value(scn, &format!("scene.materials.{smoke}.type")),
        "\"null\""
    );
    assert_eq!(
        value(scn, &format!("scene.materials.{smoke}.volume.interior")),
        "\"vol2\""
    );
    let plain = value(scn, "scene.objects.object2.material").trim_matches('"');
    assert!(
        !scn.contains(&format!("scene.materials.{plain}.volume")),
        "{scn}"
    );
}

/// Under LuxRender's default volume integrator ("emission") a homogeneous volume only
/// attenuates, so YAT renders it, and exports it, as a clear volume absorbing its extinction.
#[test]
fn homogeneous_volume_under_the_default_integrator_exports_as_clear_extinction() {
    let scene = export_world(
        r#"MakeNamedVolume "smoke" "homogeneous" "color sigma_a" [0.1 0.2 0.3] "color sigma_s" [2 2 2]
Material "null"
Interior "smoke"
Shape "sphere" "float radius" [0.5]"#,
    );
    let scn = &scene.scene;
    assert_eq!(value(scn, "scene.volumes.vol0.type"), "\"clear\"");
    let absorption = floats(value(scn, "scene.volumes.vol0.absorption"));
    for (got, want) in absorption.iter().zip([2.1f32, 2.2, 2.3]) {
        assert!((got - want).abs() < 1e-6, "{absorption:?}");
    }
    assert!(!scn.contains("scene.volumes.vol0.scattering"), "{scn}");
}

#[test]
fn subdivided_heightfield_and_quadric_shapes_export_as_their_meshes() {
    let cube = "\"integer indices\" [0 1 2 0 2 3 4 5 6 4 6 7 0 4 7 0 7 1 2 6 5 2 5 3 0 3 5 0 5 4 1 7 6 1 6 2] \
                \"point P\" [-1 -1 -1 -1 1 -1 1 1 -1 1 -1 -1 -1 -1 1 1 -1 1 1 1 1 -1 1 1]";
    let lux = export_world(&format!(
        "Shape \"loopsubdiv\" \"integer nlevels\" [2] {cube}\n\
         Shape \"heightfield\" \"integer nu\" [2] \"integer nv\" [3] \"float Pz\" [0 0 1 1 0 0]\n\
         Translate 0 0 2\nShape \"cone\" \"float radius\" [0.5]\n\
         Shape \"paraboloid\"\nShape \"hyperboloid\""
    ));
    let meshes: Vec<_> = lux
        .meshes
        .iter()
        .map(|(_, bytes)| read_mesh(bytes).expect("our PLY reads back"))
        .collect();
    let triangles: Vec<usize> = meshes.iter().map(|m| m.indices.len()).collect();
    // The subdivided cube, 2 x 2 heightfield cells, 64 x 32 quads per quadric less the 64
    // triangles that collapse where each default quadric meets the axis (the cone's apex, the
    // paraboloid's, the hyperboloid's p1 = origin).
    assert_eq!(triangles, [192, 4, 4032, 4032, 4032]);
    // Smooth normals and the quadrics' (u, v) travel with them; the cone sits 2 units up.
    assert!(meshes[0].normals.is_some() && meshes[2].uvs.is_some());
    let lowest = meshes[2]
        .positions
        .iter()
        .map(|p| p.z)
        .fold(f32::MAX, f32::min);
    assert!((lowest - 2.0).abs() < 1e-6, "{lowest}");
    assert!(
        lux.notes.iter().all(|n| !n.contains("tessellated")),
        "{:?}",
        lux.notes
    );
}

/// Light groups are LuxCore's light ids: a point light and a lamp of the second and third
/// groups carry ids 1 and 2; the first group's light keeps LuxCore's default, 0 (no id).
#[test]
fn light_groups_are_light_ids() {
    let lux = export_world(
        "LightGroup \"sky\"\nLightSource \"infinite\" \"color L\" [0.1 0.1 0.1]\n\
         LightGroup \"fill\"\nLightSource \"point\" \"point from\" [0 0 2]\n\
         LightGroup \"lamp\"\nAreaLightSource \"area\" \"color L\" [1 1 1]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 1 1 0 1 0 1 1]",
    );
    let scn = &lux.scene;
    assert!(!scn.contains("scene.lights.light0.id"), "{scn}");
    assert_eq!(value(scn, "scene.lights.light1.id"), "1");
    let lamp = scn
        .lines()
        .find(|l| l.contains(".emission.id = "))
        .unwrap_or_else(|| panic!("no emission id in\n{scn}"));
    assert!(lamp.ends_with(" = 2"), "{lamp}");
}
