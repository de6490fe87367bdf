//! The colours of bodies, shared by the 2D animation and the 3D view.

/// The palette of bodies: 20 distinct hues (Glasbey-like), then lighter and darker variants,
/// so that no two bodies of a scene with up to 60 bodies share a colour.
pub fn body_colour(i: usize) -> String {
    const BASE: [(u8, u8, u8); 20] = [
        (31, 119, 180),
        (44, 160, 44),
        (148, 103, 189),
        (140, 86, 75),
        (188, 189, 34),
        (23, 190, 207),
        (255, 127, 14),
        (127, 127, 127),
        (57, 59, 121),
        (99, 121, 57),
        (140, 109, 49),
        (132, 60, 57),
        (123, 65, 115),
        (82, 84, 163),
        (107, 110, 207),
        (156, 158, 222),
        (181, 207, 107),
        (231, 186, 82),
        (173, 73, 74),
        (206, 109, 189),
    ];
    let (r, g, b) = BASE[i % BASE.len()];
    let f = match (i / BASE.len()) % 3 {
        0 => 1.0,
        1 => 0.65,
        _ => 1.3,
    };
    let c = |v: u8| ((v as f64 * f).round().clamp(0.0, 255.0)) as u8;
    let round = i / (3 * BASE.len());
    // beyond 60 bodies, shift the hue a little so that colours still differ
    let (r, g, b) = (c(r), c(g).wrapping_add((round * 7) as u8), c(b));
    format!("#{r:02x}{g:02x}{b:02x}")
}
