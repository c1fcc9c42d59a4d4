//! `Camera "perspective" "float fov" [90] ...`: the camera's description, LuxRender's defaults
//! and their reading; cameras: perspective with an optional thin lens, orthographic, and the
//! course's fisheye.
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `fov` (perspective, fisheye) | float, degrees | 90 |
//! | `frameaspectratio` | float | the film's xresolution / yresolution |
//! | `screenwindow` | 4 floats | the longer axis spans [-aspect, aspect], the shorter [-1, 1] |
//! | `lensradius` | float | 0 |
//! | `focaldistance` | float | 1e30 (from 1e12 on: focused at infinity) |
//! | `autofocus` | bool | false: true focuses on the first hit through the screen centre |
//! | `blades` (perspective) | integer | 0: a round aperture; 3 or more a polygon ([`aperture`]) |
//! | `distribution` (perspective, 3 or more blades) | string | "uniform"; "exponential", "inverse exponential", "gaussian", "inverse gaussian" |
//! | `power` (perspective, exponential distributions) | integer | 3 (at least 1) |
//! | `hither` | float | 1e-3 (at least 1e-4) |
//! | `yon` | float | 1e30 (at least hither) |
//!
//! Other types (environment, realistic) are a warning and render as perspective. The camera
//! is placed by the transform current at the statement (world to camera).
//!
//! Film positions are raster coordinates: (0, 0) is the top-left corner of the image, x grows
//! right and y down, one unit per pixel.

pub mod aperture;
mod desc;
mod importance;
mod rays;

pub use desc::{
    CameraDesc, CameraKind, DEFAULT_CAMERA, DEFAULT_FOCAL_DISTANCE, DEFAULT_FOV, DEFAULT_HITHER,
    DEFAULT_LENS_RADIUS, DEFAULT_YON, MIN_HITHER,
};
pub use importance::CameraView;
pub use rays::{Camera, MAX_FOCAL_DISTANCE};
