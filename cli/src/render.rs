//! Flat-shaded pictures of meshes, for eyeballing simplifications.
//!
//! **Viewpoint** (fixed, so pictures of different runs compare): orthographic camera looking at
//! the centre of the mesh's bounding box (referenced vertices) along the direction
//! `-(1.0, 0.7, 1.5)` (normalised), i.e. from the +X, +Y, +Z octant, with +Y up on screen. The
//! image is [`SIZE`]×[`SIZE`] pixels; the projection of the 8 bounding-box corners fills 92 % of
//! it, so the mesh never touches the border. In `--compare` mode all four panels use the view
//! of the ORIGINAL mesh, so they line up pixel for pixel.
//!
//! **Shading**: a z-buffer rasteriser of our own writes into an `image::RgbImage` (encoded to PNG
//! by the `image` crate). Each triangle is flat shaded with `ambient + diffuse·|n·l|` for a light
//! coming from over the viewer's right shoulder. Both sides are drawn: front faces (counter-
//! clockwise on screen) in grey-blue, back faces in orange, so flipped triangles and holes show.
//! Background is white.
//!
//! **Heatmaps** (third and fourth `--compare` panels, [`render_compare`]): every visible point
//! (one per pixel) of the original is coloured by its exact distance to the result, and every
//! visible point of the result by its exact distance to the original, on one shared scale,
//! linear from 0 (blue) through cyan, green and yellow to the largest distance in either panel
//! (red), see [`heat_colour`]. Both directions are needed: the result's distance to the original
//! cannot show surface the result lost (a part cut away, a hole cut through), because nothing of
//! the result is there to be coloured; the original's distance to the result shows it hot. A
//! colour bar and captions (a small bitmap font, `render/text.rs`) under the panels say which
//! panel is which and what red stands for. (Colouring by per-vertex error would show nothing:
//! tinydecimate keeps original vertices, so every output vertex lies on the original surface.)

use std::path::Path;

use anyhow::{Context, Result};
use image::{ImageFormat, Rgb, RgbImage};

use crate::io::MeshData;

mod text;
pub mod textured;

/// Width and height of one picture, in pixels.
pub const SIZE: u32 = 512;
/// Direction from the scene towards the camera (before normalisation).
pub const EYE_DIRECTION: [f64; 3] = [1.0, 0.7, 1.5];
/// Background colour.
pub const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const FRONT: [f64; 3] = [190.0, 200.0, 220.0];
const BACK: [f64; 3] = [235.0, 150.0, 90.0];
const FILL: f64 = 0.92;

use crate::vec3::{cross, dot, normalize, V3};

/// An orthographic camera.
#[derive(Clone, Copy, Debug)]
pub struct View {
    centre: V3,
    right: V3,
    up: V3,
    /// Viewing direction (from the camera into the scene).
    forward: V3,
    /// Pixels per model unit.
    scale: f64,
    light: V3,
}

impl View {
    /// The fixed view of `mesh`: see the module documentation.
    pub fn fit(mesh: &MeshData) -> View {
        let (lo, hi) = mesh.bbox().unwrap_or(([-1.0; 3], [1.0; 3]));
        let centre = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0);
        let forward = normalize(EYE_DIRECTION.map(|c| -c));
        let right = normalize(cross(forward, [0.0, 1.0, 0.0]));
        let up = cross(right, forward);
        let mut extent: f64 = 0.0;
        for corner in 0..8 {
            let p = [0, 1, 2].map(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            let d = [0, 1, 2].map(|k| p[k] - centre[k]);
            extent = extent.max(dot(d, right).abs()).max(dot(d, up).abs());
        }
        let scale = if extent > 0.0 {
            f64::from(SIZE) / 2.0 * FILL / extent
        } else {
            1.0
        };
        // Light from over the viewer's right shoulder.
        let light = normalize([0, 1, 2].map(|k| -forward[k] + 0.4 * right[k] + 0.6 * up[k]));
        View {
            centre,
            right,
            up,
            forward,
            scale,
            light,
        }
    }

    /// Direction towards the light (unit length).
    pub fn light(&self) -> V3 {
        self.light
    }

    /// Pixel coordinates (x right, y down) and depth (larger is farther) of a point.
    pub fn project(&self, p: V3) -> V3 {
        let d = [0, 1, 2].map(|k| p[k] - self.centre[k]);
        let half = f64::from(SIZE) / 2.0;
        [
            half + dot(d, self.right) * self.scale,
            half - dot(d, self.up) * self.scale,
            dot(d, self.forward),
        ]
    }
}

/// Heatmap colour of `t` in `[0, 1]` (clamped): blue, cyan, green, yellow, red at 0, ¼, ½, ¾, 1.
pub fn heat_colour(t: f64) -> [f64; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [0.0, 0.0, 255.0],
        [0.0, 255.0, 255.0],
        [0.0, 255.0, 0.0],
        [255.0, 255.0, 0.0],
        [255.0, 0.0, 0.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    } * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    [0, 1, 2].map(|k| STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f)
}

/// What the z-buffer keeps for a covered pixel.
#[derive(Clone, Copy, Debug)]
struct Hit {
    /// The surface point seen (model space).
    point: V3,
    /// `|n·l|` of its triangle.
    lambert: f64,
    /// Whether its triangle faces the camera.
    front: bool,
}

/// Z-buffer rasterisation of `mesh`: the nearest surface point per pixel (row-major), sampled
/// at pixel centres.
fn rasterise(mesh: &MeshData, view: &View) -> Vec<Option<Hit>> {
    let (w, h) = (SIZE as usize, SIZE as usize);
    let mut depth = vec![f64::INFINITY; w * h];
    let mut hits: Vec<Option<Hit>> = vec![None; w * h];
    let n = mesh.positions.len();
    for t in &mesh.triangles {
        if t.iter().any(|&i| i as usize >= n) {
            continue;
        }
        let p = t.map(|i| mesh.positions[i as usize].map(f64::from));
        let normal = normalize(cross(
            [0, 1, 2].map(|k| p[1][k] - p[0][k]),
            [0, 1, 2].map(|k| p[2][k] - p[0][k]),
        ));
        let front = dot(normal, view.forward) < 0.0;
        let lambert = dot(normal, view.light).abs();
        let s = p.map(|q| view.project(q));
        let area =
            (s[1][0] - s[0][0]) * (s[2][1] - s[0][1]) - (s[2][0] - s[0][0]) * (s[1][1] - s[0][1]);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        let min = |k: usize| s.iter().map(|v| v[k]).fold(f64::INFINITY, f64::min);
        let max = |k: usize| s.iter().map(|v| v[k]).fold(f64::NEG_INFINITY, f64::max);
        let (x0, x1) = (min(0).floor().max(0.0), max(0).ceil().min(w as f64 - 1.0));
        let (y0, y1) = (min(1).floor().max(0.0), max(1).ceil().min(h as f64 - 1.0));
        if x1 < x0 || y1 < y0 {
            continue;
        }
        for y in y0 as usize..=y1 as usize {
            for x in x0 as usize..=x1 as usize {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let e = |a: V3, b: V3| (b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1]);
                let w0 = e(s[1], s[2]) / area;
                let w1 = e(s[2], s[0]) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * s[0][2] + w1 * s[1][2] + w2 * s[2][2];
                let slot = &mut depth[y * w + x];
                if z >= *slot {
                    continue;
                }
                *slot = z;
                let point = [0, 1, 2].map(|k| w0 * p[0][k] + w1 * p[1][k] + w2 * p[2][k]);
                hits[y * w + x] = Some(Hit {
                    point,
                    lambert,
                    front,
                });
            }
        }
    }
    hits
}

fn shaded(base: [f64; 3], shade: f64) -> Rgb<u8> {
    Rgb(base.map(|c| (c * shade).round().clamp(0.0, 255.0) as u8))
}

fn image_of(hits: &[Option<Hit>], colour: impl Fn(usize, &Hit) -> Rgb<u8>) -> RgbImage {
    let mut img = RgbImage::from_pixel(SIZE, SIZE, BACKGROUND);
    for (i, hit) in hits.iter().enumerate() {
        if let Some(h) = hit {
            img.put_pixel(i as u32 % SIZE, i as u32 / SIZE, colour(i, h));
        }
    }
    img
}

/// Draws `mesh` from `view`, flat shaded, into a new [`SIZE`]² image.
pub fn render(mesh: &MeshData, view: &View) -> RgbImage {
    image_of(&rasterise(mesh, view), |_, h| {
        shaded(if h.front { FRONT } else { BACK }, 0.25 + 0.75 * h.lambert)
    })
}

/// Per pixel of `mesh` seen from `view`: what the z-buffer keeps and the distance of that
/// surface point to the surface of `reference` (infinite when `reference` has no triangle).
fn distances(mesh: &MeshData, view: &View, reference: &MeshData) -> (Vec<Option<Hit>>, Vec<f64>) {
    use rayon::prelude::*;
    let hits = rasterise(mesh, view);
    let bvh = crate::metro::Bvh::new(reference);
    let dist: Vec<f64> = hits
        .par_iter()
        .map(|h| h.map_or(0.0, |h| bvh.closest(h.point, usize::MAX).0.sqrt()))
        .collect();
    (hits, dist)
}

/// The largest finite distance of `dist`, 0 if none.
fn largest(dist: &[f64]) -> f64 {
    dist.iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max)
}

/// The heatmap image of [`distances`]' output: red is `top` and more (and an infinite distance:
/// nothing of the reference to be near).
fn heat_image(hits: &[Option<Hit>], dist: &[f64], top: f64) -> RgbImage {
    image_of(hits, |i, h| {
        let t = if !dist[i].is_finite() {
            1.0
        } else if top > 0.0 {
            dist[i] / top
        } else {
            0.0
        };
        shaded(heat_colour(t), 0.45 + 0.55 * h.lambert)
    })
}

/// Draws `mesh` from `view` coloured by the distance of each visible surface point (one per
/// pixel) to the surface of `reference`, scaled so that red is the largest distance seen.
/// Returns the image and that largest distance.
pub fn render_heat(mesh: &MeshData, view: &View, reference: &MeshData) -> (RgbImage, f64) {
    let (hits, dist) = distances(mesh, view, reference);
    let top = largest(&dist);
    (heat_image(&hits, &dist, top), top)
}

/// The scale of a `--compare` picture: the largest distance seen in each heatmap panel. Red
/// stands for [`Scale::top`], the larger of the two.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// Largest distance of a visible point of the original to the result: surface the result
    /// lost (a part cut away, a hole) shows here.
    pub original_to_result: f64,
    /// Largest distance of a visible point of the result to the original: surface the result
    /// moved or added shows here.
    pub result_to_original: f64,
}

impl Scale {
    /// The distance red stands for in both heatmap panels.
    pub fn top(&self) -> f64 {
        self.original_to_result.max(self.result_to_original)
    }
}

/// Height of the caption strip under the `--compare` panels, in pixels.
pub const CAPTION: u32 = 80;

/// The captions of the four `--compare` panels: a name and a line on what the colours mean.
pub const PANEL_CAPTIONS: [[&str; 2]; 4] = [
    ["original", ""],
    ["result", "back faces orange"],
    [
        "original: distance to result",
        "hot = surface the result lost",
    ],
    [
        "result: distance to original",
        "hot = result surface off the original",
    ],
];

/// The `--compare` picture: four panels side by side, all from the original's view, over a
/// caption strip ([`CAPTION`] pixels, [`PANEL_CAPTIONS`]): the original, the result, the
/// original coloured by its distance to the result and the result coloured by its distance to
/// the original (per pixel, see [`render_heat`]). Both heatmaps share one scale, drawn as a
/// colour bar under them: blue 0, red [`Scale::top`]. A part the result lost has nothing of the
/// result near it, so it is hot in the third panel (and absent from the fourth).
pub fn render_compare(original: &MeshData, simplified: &MeshData) -> (RgbImage, Scale) {
    let view = View::fit(original);
    let (ohits, odist) = distances(original, &view, simplified);
    let (shits, sdist) = distances(simplified, &view, original);
    let scale = Scale {
        original_to_result: largest(&odist),
        result_to_original: largest(&sdist),
    };
    let top = scale.top();
    let panels = [
        render(original, &view),
        render(simplified, &view),
        heat_image(&ohits, &odist, top),
        heat_image(&shits, &sdist, top),
    ];
    let mut out = RgbImage::from_pixel(4 * SIZE, SIZE + CAPTION, BACKGROUND);
    for (k, panel) in panels.iter().enumerate() {
        image::imageops::replace(&mut out, panel, i64::from(k as u32 * SIZE), 0);
    }
    let ink = Rgb([40, 40, 40]);
    for (k, [name, hint]) in PANEL_CAPTIONS.iter().enumerate() {
        let x = k as u32 * SIZE + 12;
        text::draw(&mut out, x, SIZE + 6, name, ink);
        text::draw(
            &mut out,
            x,
            SIZE + 10 + text::HEIGHT,
            hint,
            Rgb([110, 110, 110]),
        );
    }
    // One colour bar under both heatmaps, with its two ends' values.
    let (bx0, bx1) = (2 * SIZE + 12, 4 * SIZE - 12);
    let (by0, by1) = (SIZE + 14 + 2 * text::HEIGHT, SIZE + 24 + 2 * text::HEIGHT);
    for x in bx0..bx1 {
        let c = heat_colour(f64::from(x - bx0) / f64::from(bx1 - 1 - bx0));
        for y in by0..by1 {
            out.put_pixel(x, y, Rgb(c.map(|v| v as u8)));
        }
    }
    text::draw(&mut out, bx0, by1 + 4, "0", ink);
    let diag = original.bbox_diagonal();
    let pct = if diag > 0.0 { 100.0 * top / diag } else { 0.0 };
    let red = format!("{} = {pct:.4} % of the diagonal", four_digits(top)).to_uppercase();
    text::draw(&mut out, bx1 - text::width(&red), by1 + 4, &red, ink);
    // Thin separators between panels.
    for x in [SIZE, 2 * SIZE, 3 * SIZE] {
        for y in 0..SIZE {
            out.put_pixel(x, y, Rgb([160, 160, 160]));
        }
    }
    (out, scale)
}

/// `d` to four significant digits, in positional notation from 0.001 to 99 999.
fn four_digits(d: f64) -> String {
    let e = if d != 0.0 && d.is_finite() {
        d.abs().log10().floor()
    } else {
        0.0
    };
    if (-3.0..5.0).contains(&e) {
        format!("{d:.*}", (3.0 - e).max(0.0) as usize)
    } else {
        format!("{d:.3e}")
    }
}

/// Draws `mesh` (or the comparison with `compare`) into the PNG file `out`.
pub fn draw(mesh: &Path, out: &Path, compare: Option<&Path>) -> Result<()> {
    if crate::gltf::is_gltf_path(mesh) {
        return crate::render::textured::draw(mesh, out, compare);
    }
    let m = crate::io::load_noting(mesh)?;
    let img = match compare {
        None => render(&m, &View::fit(&m)),
        Some(orig) => {
            let o = crate::io::load_noting(orig)?;
            let (img, scale) = render_compare(&o, &m);
            let diag = o.bbox_diagonal();
            let pct = |d: f64| if diag > 0.0 { 100.0 * d / diag } else { 0.0 };
            let top = scale.top();
            crate::outln!(
                "panels: original | result | original coloured by its distance to the result \
                 (missing surface is hot) | result coloured by its distance to the original"
            );
            crate::outln!(
                "scale (both heatmaps): blue = 0, red = {top:.6e} = {:.4} % of the original's \
                 bbox diagonal",
                pct(top)
            );
            crate::outln!(
                "largest seen: original -> result {:.6e} ({:.4} %), result -> original {:.6e} \
                 ({:.4} %)",
                scale.original_to_result,
                pct(scale.original_to_result),
                scale.result_to_original,
                pct(scale.result_to_original)
            );
            img
        }
    };
    img.save_with_format(out, ImageFormat::Png)
        .with_context(|| format!("{}: cannot write PNG", out.display()))?;
    crate::outln!("wrote {} ({}x{})", out.display(), img.width(), img.height());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> MeshData {
        let mut positions = Vec::new();
        for i in 0..8 {
            positions.push([(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32]);
        }
        // Outward-facing (counter-clockwise seen from outside).
        let triangles = vec![
            [0, 2, 3],
            [0, 3, 1], // z = 0
            [4, 5, 7],
            [4, 7, 6], // z = 1
            [0, 1, 5],
            [0, 5, 4], // y = 0
            [2, 6, 7],
            [2, 7, 3], // y = 1
            [0, 4, 6],
            [0, 6, 2], // x = 0
            [1, 3, 7],
            [1, 7, 5], // x = 1
        ];
        MeshData {
            positions,
            triangles,
        }
    }

    fn colours(img: &RgbImage) -> std::collections::HashSet<[u8; 3]> {
        img.pixels()
            .filter(|p| **p != BACKGROUND)
            .map(|p| p.0)
            .collect()
    }

    #[test]
    fn cube_png_has_expected_size_and_three_front_faces() {
        let dir = tempfile::tempdir().unwrap();
        let obj = dir.path().join("cube.obj");
        let png = dir.path().join("cube.png");
        crate::io::save(&obj, &cube()).unwrap();
        draw(&obj, &png, None).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (SIZE, SIZE));
        let drawn = img.pixels().filter(|p| **p != BACKGROUND).count();
        assert!(drawn > (SIZE * SIZE / 5) as usize, "{drawn}");
        // Three visible faces, three shades, all front-facing (no orange).
        let c = colours(&img);
        assert_eq!(c.len(), 3, "{c:?}");
        assert!(c.iter().all(|p| p[2] > p[0]));
        // Corners stay background (the fit leaves a margin).
        assert_eq!(*img.get_pixel(0, 0), BACKGROUND);
        assert_eq!(*img.get_pixel(SIZE - 1, SIZE - 1), BACKGROUND);
    }

    #[test]
    fn inside_out_cube_is_orange_and_compare_has_four_panels() {
        let mut flipped = cube();
        for t in &mut flipped.triangles {
            t.swap(1, 2);
        }
        let img = render(&flipped, &View::fit(&flipped));
        assert!(colours(&img).iter().all(|p| p[0] > p[2]));

        let mut bumped = cube();
        bumped.positions[7] = [1.2, 1.2, 1.2];
        let (img, scale) = render_compare(&cube(), &bumped);
        assert_eq!(img.dimensions(), (4 * SIZE, SIZE + CAPTION));
        let top = scale.top();
        assert!(top > 0.1 && top <= 0.2 * 3f64.sqrt() + 1e-9, "{top}");
        assert!(scale.original_to_result > 0.0 && scale.result_to_original > 0.0);
        // The result's heatmap has red near the bumped corner and blue elsewhere.
        let heat: Vec<[u8; 3]> = (3 * SIZE + 1..4 * SIZE)
            .flat_map(|x| (0..SIZE).map(move |y| (x, y)))
            .map(|(x, y)| img.get_pixel(x, y).0)
            .collect();
        assert!(heat.iter().any(|p| p[0] > 150 && p[1] < 80 && p[2] < 80));
        assert!(heat.iter().any(|p| p[2] > 150 && p[0] < 80));
        // Every panel has its caption: ink in the strip under it.
        for k in 0..4 {
            let ink = (k * SIZE + 1..(k + 1) * SIZE)
                .flat_map(|x| (SIZE..SIZE + CAPTION).map(move |y| (x, y)))
                .filter(|&(x, y)| *img.get_pixel(x, y) != BACKGROUND)
                .count();
            assert!(ink > 100, "panel {k}: {ink}");
        }
    }

    /// An axis-aligned cube of side `side` at `at`, its triangles numbered from `first`.
    fn cube_at(at: [f32; 3], side: f32, first: u32) -> MeshData {
        let mut c = cube();
        for p in &mut c.positions {
            *p = [0, 1, 2].map(|k| at[k] + side * p[k]);
        }
        for t in &mut c.triangles {
            *t = t.map(|i| i + first);
        }
        c
    }

    /// Whether a heatmap pixel is in the hot half of the scale (green to red: no blue) and drawn.
    fn hot(p: [u8; 3]) -> bool {
        p != BACKGROUND.0 && p[2] == 0 && (p[0] > 0 || p[1] > 0)
    }

    /// Whether a heatmap pixel is at the cold end (blue, no red).
    fn cold(p: [u8; 3]) -> bool {
        p != BACKGROUND.0 && p[0] == 0 && p[2] > 0
    }

    #[test]
    fn a_part_cut_away_is_hot_in_the_original_panel() {
        // Two cubes; the result lost the small one (the nearer to the camera).
        let kept = cube_at([0.0; 3], 1.0, 0);
        let lost = cube_at([3.0; 3], 0.5, 8);
        let original = MeshData {
            positions: [kept.positions.clone(), lost.positions].concat(),
            triangles: [kept.triangles.clone(), lost.triangles].concat(),
        };
        let (img, scale) = render_compare(&original, &kept);
        // The lost cube is 12^0.5 to 18.75^0.5 from the kept one; the result lies on the original.
        assert!(
            (scale.original_to_result - 18.75f64.sqrt()).abs() < 0.05,
            "{scale:?}"
        );
        assert!(scale.result_to_original < 1e-9, "{scale:?}");
        let view = View::fit(&original);
        let (mut lost_px, mut kept_px) = (0, 0);
        for (i, h) in rasterise(&original, &view).iter().enumerate() {
            let Some(h) = h else { continue };
            let (x, y) = (i as u32 % SIZE, i as u32 / SIZE);
            let third = img.get_pixel(2 * SIZE + x, y).0;
            let fourth = img.get_pixel(3 * SIZE + x, y).0;
            if h.point[0] > 2.9 {
                // The lost part: hot beside, nothing of the result in the fourth panel.
                lost_px += 1;
                assert!(hot(third), "({x}, {y}): {third:?}");
                assert_eq!(fourth, BACKGROUND.0, "({x}, {y})");
            } else {
                // Kept surface: at distance 0 in both heatmaps.
                kept_px += 1;
                assert!(cold(third), "({x}, {y}): {third:?}");
                assert!(cold(fourth), "({x}, {y}): {fourth:?}");
            }
        }
        assert!(lost_px > 1000 && kept_px > 1000, "{lost_px} {kept_px}");
    }

    #[test]
    fn a_hole_cut_through_is_hot_at_its_centre() {
        // A 10 x 10 plate; the result lost its middle 4 x 4 quads.
        let n = 10u32;
        let positions = (0..(n + 1) * (n + 1))
            .map(|i| {
                [
                    (i % (n + 1)) as f32 / n as f32,
                    (i / (n + 1)) as f32 / n as f32,
                    0.0,
                ]
            })
            .collect();
        let (mut all, mut holed) = (Vec::new(), Vec::new());
        for y in 0..n {
            for x in 0..n {
                let a = y * (n + 1) + x;
                let quad = [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]];
                all.extend(quad);
                if !((3..7).contains(&x) && (3..7).contains(&y)) {
                    holed.extend(quad);
                }
            }
        }
        let original = MeshData {
            positions,
            triangles: all,
        };
        let result = MeshData {
            positions: original.positions.clone(),
            triangles: holed,
        };
        let (img, scale) = render_compare(&original, &result);
        assert!((scale.original_to_result - 0.2).abs() < 0.01, "{scale:?}");
        let view = View::fit(&original);
        let at = |p: V3, panel: u32| {
            let s = view.project(p);
            img.get_pixel(panel * SIZE + s[0] as u32, s[1] as u32).0
        };
        // The hole's centre: hot in the original's heatmap, bare in the result's.
        assert!(hot(at([0.5, 0.5, 0.0], 2)), "{:?}", at([0.5, 0.5, 0.0], 2));
        assert_eq!(at([0.5, 0.5, 0.0], 3), BACKGROUND.0);
        // Kept plate: cold in both.
        for p in [[0.1, 0.1, 0.0], [0.9, 0.15, 0.0], [0.15, 0.85, 0.0]] {
            assert!(cold(at(p, 2)), "{p:?}: {:?}", at(p, 2));
            assert!(cold(at(p, 3)), "{p:?}: {:?}", at(p, 3));
        }
    }

    #[test]
    fn captions_have_every_glyph() {
        assert_eq!(four_digits(52.94931), "52.95");
        assert_eq!(four_digits(0.0012345), "0.001234");
        assert_eq!(four_digits(4.198798), "4.199");
        assert_eq!(four_digits(12345.6), "12346");
        assert_eq!(four_digits(0.0), "0.000");
        // The colour bar's value, as render_compare writes it.
        let red =
            format!("{} = {:.4} % of the diagonal", four_digits(1.234e-5), 12.5).to_uppercase();
        for s in PANEL_CAPTIONS.iter().flatten().chain([&red.as_str()]) {
            assert!(s.chars().all(|c| text::glyph(c).is_some()), "{s}");
            assert!(text::width(s) + 12 < SIZE, "{s}");
        }
    }

    #[test]
    fn heat_colour_stops() {
        assert_eq!(heat_colour(0.0), [0.0, 0.0, 255.0]);
        assert_eq!(heat_colour(0.5), [0.0, 255.0, 0.0]);
        assert_eq!(heat_colour(1.0), [255.0, 0.0, 0.0]);
        assert_eq!(heat_colour(7.0), [255.0, 0.0, 0.0]);
        assert_eq!(heat_colour(f64::NAN), [255.0, 0.0, 0.0]);
    }
}
