//! Cameras: perspective, thin lens, fisheye (the course's), orthographic.
