//! The tracer's integration tests, one binary: the parser against its conventions and against
//! malformed input, whole renders with numbers, and the seed scenes when they are present.

mod adaptive;
mod alpha;
mod aovs;
mod area_texture;
mod bidirectional;
mod branching;
mod bump_render;
mod camera_lens;
mod daylight;
mod direct_lighting;
mod dispersion;
mod estimates;
mod geometry_on_scenes;
mod glossy_lossy;
mod glossy_split;
#[path = "../../../tests/fixtures/hostile.rs"]
mod hostile;
mod hostile_scenes;
mod image_formats;
mod light_groups;
mod luxrender_materials;
mod mirror_images;
mod outliers;
mod panes;
mod parse_conventions;
mod parse_errors;
mod render;
#[path = "../../../tests/fixtures/scene.rs"]
mod scene;
mod seed_renders;
mod seed_scenes;
mod shapes;
mod spectral_textures;
mod statistics;
mod thin_film;
#[path = "../../../tests/fixtures/workspace.rs"]
mod util;
mod volumes;
