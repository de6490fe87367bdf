//! Animations of a solved motion (`bondmech animate`): one self-contained file, an SVG animated
//! with SMIL or an HTML page with the same SVG inline and a few lines of script for its
//! controls. Nothing is fetched from the network.
//!
//! What is drawn, from the scene and the solution's columns (`b.x, b.y, b.angle` for a planar
//! body; `b.x, b.y, b.z` and the attitude — the quaternion `b.qw…b.qz`, or else the Cardan
//! angles `b.psi, b.theta, b.phi` — for a spatial one):
//! - each body (colours from [`body_colour`], which do not repeat within 60 bodies) as arms
//!   from its centre of mass to each of its points (a bar between its two end
//!   points), a translucent polygon through its points when it has three or more, a dot at the
//!   centre of mass; a point mass (no rotational inertia) as a large dot;
//! - joints as circles at the joint point (a weld as a square), a slider as a block on its rail
//!   (the rail is fixed to the slider's first body and spans the travel), springs as dashed
//!   lines, ground attachments with a hatched ground mark;
//! - the path of every requested body point (`"outputs": ["bar2.A"]`) as a faint trace, with a
//!   marker at the point's current position;
//! - a time label, a scale bar and the view's axes.
//!
//! 3D scenes are drawn in an orthographic view (`xy`, `xz`, `yz`, or isometric `iso`: x towards
//! the lower left, y towards the lower right, z up). A point `p` of the world maps to the pixel
//! `(ox + s·(r·p), oy − s·(u·p))`, where `r` and `u` are the view's right and up directions; the
//! root `<svg>` element states them as `data-right`, `data-up`, `data-scale` and `data-origin`,
//! so other tools (and the tests) can locate any point in the picture.
//!
//! The frames are rows of the solution: those nearest to `t₀ + k·speed/fps`, plus the rows
//! needed so that no body turns more than [`MAX_TURN_DEGREES`] or moves more than
//! [`MAX_MOVE_FRACTION`] of its size between two frames (poses interpolated between rows that
//! are further apart; [`denser_output_times`] tells a caller that can solve again which times
//! avoid that). A planar body is one SVG group moved by its pose (SMIL interpolates its centre
//! and angle), so it stays rigid between frames; a spatial scene's HTML page is the 3D view of
//! [`super::view3d`]. The animation lasts `(t_end − t₀) / speed` seconds and loops; without a
//! given speed, fast motions are slowed and the picture says so. Appending `#t=0.7` (or
//! `?t=0.7`) to the file's URL opens it paused at t = 0.7 s of the motion; [`frames_json`]
//! gives the frames exactly as drawn.

pub use super::palette::body_colour;
use super::view3d::FramePose;
use std::fmt::Write;

use super::error::{ReportError, Result};
use crate::mech::joints::{glyph, Glyph};
use crate::scene::{Body, Dimension, Inertia, PointRef, Scene, GROUND};
use crate::solve::Solution;

mod drawing;
mod frames;
mod page3d;
mod pose;
mod svg;

use drawing::*;
use frames::*;
use page3d::*;
use pose::*;
use svg::*;

pub use frames::{denser_output_times, frames_json, Frame, MAX_MOVE_FRACTION, MAX_TURN_DEGREES};
pub use page3d::{view3d_json, view3d_script};

/// The orthographic view of the animation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Looking down the z axis: x right, y up (the plane of a planar scene).
    Xy,
    /// Looking along +y: x right, z up.
    Xz,
    /// Looking along −x: y right, z up.
    Yz,
    /// Isometric, from (1, 1, 1): x to the lower left, y to the lower right, z up.
    Iso,
}

impl View {
    /// The view's name (`xy`, `xz`, `yz`, `iso`).
    pub fn as_str(self) -> &'static str {
        match self {
            View::Xy => "xy",
            View::Xz => "xz",
            View::Yz => "yz",
            View::Iso => "iso",
        }
    }

    /// Parses a view name.
    pub fn parse(name: &str) -> Option<View> {
        [View::Xy, View::Xz, View::Yz, View::Iso]
            .into_iter()
            .find(|v| v.as_str() == name)
    }

    /// The screen's right and up directions in world coordinates (orthonormal).
    pub fn axes(self) -> ([f64; 3], [f64; 3]) {
        match self {
            View::Xy => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            View::Xz => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            View::Yz => ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            View::Iso => {
                let (a, b) = (1.0 / 2f64.sqrt(), 1.0 / 6f64.sqrt());
                ([-a, a, 0.0], [-b, -b, 2.0 * b])
            }
        }
    }
}

/// The file format of an animation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationFormat {
    /// An SVG animated with SMIL (opens in any browser; `#t=T` pauses it at time T).
    Svg,
    /// An HTML page with the SVG inline, a play/pause button and a time slider.
    Html,
}

/// How to animate.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationOptions {
    /// Frames per second of playback (> 0).
    pub fps: f64,
    /// Seconds of motion per second of playback (> 0; 0.5 is slow motion); `None`: 1, or
    /// slower (a 1-2-5 value) when a body would turn more than [`MAX_TURN_DEGREES`] in one
    /// frame of playback — the page says so.
    pub speed: Option<f64>,
    /// The view; `None`: `xy` for a planar scene, `iso` for a spatial one.
    pub view: Option<View>,
    /// Picture width in pixels.
    pub width: u32,
    /// Picture height in pixels.
    pub height: u32,
    /// Where the solution came from (a file name), for error messages.
    pub source: String,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        AnimationOptions {
            fps: 30.0,
            speed: None,
            view: None,
            width: 800,
            height: 600,
            source: "the solution".into(),
        }
    }
}

/// The largest number of frames an animation may have.
pub const MAX_FRAMES: usize = 20_000;

/// Trace colours; the first is the marker colour the tests look for.
pub const TRACE_COLOURS: [(u8, u8, u8); 3] = [(230, 0, 126), (255, 127, 14), (214, 39, 40)];
const INK: &str = "#222";

/// Refuses a frame rate or speed that is not a positive number.
fn check_options(opts: &AnimationOptions) -> Result<()> {
    if !(opts.fps > 0.0 && opts.fps.is_finite()) {
        return Err(ReportError::NotPositive {
            option: "--fps",
            value: opts.fps,
        });
    }
    if let Some(speed) = opts.speed {
        if !(speed > 0.0 && speed.is_finite()) {
            return Err(ReportError::NotPositive {
                option: "--speed",
                value: speed,
            });
        }
    }
    Ok(())
}

/// Renders the animation of `sol` (a solution of `scene`, solved or read from a CSV that
/// `bondmech run` wrote) as one self-contained SVG or HTML document.
pub fn animation(
    scene: &Scene,
    sol: &Solution,
    opts: &AnimationOptions,
    format: AnimationFormat,
) -> Result<String> {
    check_options(opts)?;
    let view = opts.view.unwrap_or(match scene.dimension {
        Dimension::Planar => View::Xy,
        Dimension::Spatial => View::Iso,
    });
    if scene.dimension == Dimension::Planar && view != View::Xy {
        return Err(ReportError::PlanarView {
            view: view.as_str(),
        });
    }
    if format == AnimationFormat::Html && scene.dimension == Dimension::Spatial {
        return page_3d(scene, sol, opts);
    }
    let drawing = build_drawing(scene, sol, opts)?;
    Ok(match format {
        AnimationFormat::Svg => {
            let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
            s.push_str(&svg_document(scene, &drawing, opts, view, true));
            s
        }
        AnimationFormat::Html => format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{} — bondmech</title>\n\
             <style>body{{margin:0;font-family:Helvetica,Arial,sans-serif}}#controls{{padding:6px 12px}}\
             #controls button{{width:5em}}#controls input{{width:520px;vertical-align:middle}}</style></head>\n<body>\n{}\
             <div id=\"controls\"><button id=\"play\">play</button> <input id=\"time\" type=\"range\"> <span id=\"readout\"></span></div>\n\
             <script>\n{HTML_SCRIPT}\n</script>\n</body></html>\n",
            xml(&scene.name),
            svg_document(scene, &drawing, opts, view, false)
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_are_orthonormal_and_right_handed() {
        for v in [View::Xy, View::Xz, View::Yz, View::Iso] {
            let (r, u) = v.axes();
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            assert!((dot(r, r) - 1.0).abs() < 1e-15 && (dot(u, u) - 1.0).abs() < 1e-15);
            assert!(dot(r, u).abs() < 1e-15);
            assert_eq!(View::parse(v.as_str()), Some(v));
        }
        // iso: the viewer sits on the (1, 1, 1) diagonal, z up on the screen
        let (r, u) = View::Iso.axes();
        let towards_viewer = [
            r[1] * u[2] - r[2] * u[1],
            r[2] * u[0] - r[0] * u[2],
            r[0] * u[1] - r[1] * u[0],
        ];
        for c in towards_viewer {
            assert!((c - 1.0 / 3f64.sqrt()).abs() < 1e-15);
        }
    }

    fn planar(angle: f64, x: f64) -> Pose {
        let (sn, c) = angle.sin_cos();
        Pose {
            r: [x, 0.0, 0.0],
            rot: [[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    #[test]
    fn intervals_are_cut_so_that_no_body_turns_more_than_15_degrees() {
        let a = [planar(0.0, 0.0)];
        assert_eq!(
            parts_needed(&a, &[planar(14f64.to_radians(), 0.0)], &[1.0]),
            1
        );
        assert_eq!(
            parts_needed(&a, &[planar(15f64.to_radians(), 0.0)], &[1.0]),
            1
        );
        assert_eq!(
            parts_needed(&a, &[planar(16f64.to_radians(), 0.0)], &[1.0]),
            2
        );
        assert_eq!(
            parts_needed(&a, &[planar(-100f64.to_radians(), 0.0)], &[1.0]),
            7
        );
        // or move more than a tenth of its size: 0.35 m for a body of 1 m is 4 parts
        assert_eq!(parts_needed(&a, &[planar(0.0, 0.35)], &[1.0]), 4);
        assert!((turn_angle(&a[0], &planar(0.3, 0.0)) - 0.3).abs() < 1e-15);
        // halfway between two poses: the angle halfway, the body rigid
        let m = interpolate_pose(&a[0], &planar(1.0, 2.0), 0.5);
        assert!((turn_angle(&a[0], &m) - 0.5).abs() < 1e-12 && (m.r[0] - 1.0).abs() < 1e-15);
        // unwrapped angles go on past ±π
        let frames: Vec<Vec<Pose>> = (0..10).map(|k| vec![planar(k as f64, 0.0)]).collect();
        let un = planar_angles(&frames);
        for (k, a) in un.iter().enumerate() {
            assert!((a[0] - k as f64).abs() < 1e-12, "{k}: {}", a[0]);
        }
        assert_eq!(nice_floor(0.07), 0.05);
        assert_eq!(nice_floor(1.0), 1.0);
        assert_eq!(nice_floor(0.3), 0.2);
    }

    #[test]
    fn the_palette_does_not_repeat_within_sixty_bodies() {
        let c: std::collections::BTreeSet<String> = (0..60).map(body_colour).collect();
        assert_eq!(c.len(), 60);
        assert_eq!(body_colour(1), "#2ca02c");
    }

    #[test]
    fn nice_lengths_are_one_two_five() {
        assert_eq!(nice_length(4.0), 1.0);
        assert_eq!(nice_length(9.0), 2.0);
        assert_eq!(nice_length(2.2), 0.5);
    }
}
