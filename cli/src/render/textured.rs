//! Textured pictures of glTF models: `tinydecimate render OUT.glb out.png --compare IN.glb` draws
//! the original | the simplified model | the simplified model with its triangle edges, each
//! with its base colour texture, so a person sees at once whether seams and texture held.
//!
//! The scene is drawn as a viewer would place it ([`crate::io::gltf::placements`]): every node
//! of the default scene (or of the first, or every root node when there is no scene) with its
//! world transform (`matrix` or translation/rotation/scale, composed down the node tree), so a
//! mesh that several nodes place is drawn once per node. The triangle counts printed are the
//! file's, each primitive once, as `simplify` and every other command count them; when the
//! scene draws another number (instancing, or a mesh no node places) the output says so:
//! "2856 triangles, 3624 drawn: mesh 1 drawn 2 times". Each triangle primitive is drawn
//! with its material's `baseColorTexture` (sampled bilinearly at the interpolated
//! `TEXCOORD_n` it names, wrapped as its sampler says) times `baseColorFactor`; a primitive with
//! no texture is drawn in its factor's colour, one with no material in light grey. Shading is
//! `0.35 + 0.65·|n·l|` per triangle, with [`crate::render`]'s camera and light, fitted to the
//! original so the panels line up pixel for pixel. `KHR_texture_transform` and vertex colours
//! are not applied.

use std::path::Path;

use anyhow::{anyhow, Context, Result};
use image::{ImageFormat, Rgb, RgbImage, RgbaImage};
use serde_json::Value;

use crate::io::gltf::{GltfFile, Instancing, Transform};
use crate::io::MeshData;
use crate::render::{View, BACKGROUND, SIZE};

/// Colour of a primitive without a material (glTF's default material is white; light grey
/// keeps shading visible).
const NO_MATERIAL: [f64; 4] = [0.85, 0.85, 0.85, 1.0];
/// Triangle edges in the third panel.
const EDGE: [f64; 3] = [20.0, 20.0, 20.0];

/// A material as drawn: a colour factor and, when it has one, a texture with its wrap modes.
struct Material {
    factor: [f64; 4],
    texture: Option<Texture>,
    /// Which `TEXCOORD_n` the texture reads.
    tex_coord: usize,
}

struct Texture {
    image: RgbaImage,
    /// Sampler `wrapS`, `wrapT` (10497 repeat, 33648 mirrored repeat, 33071 clamp).
    wrap: [u64; 2],
}

/// A glTF scene flattened into world space: one triangle list with a UV per corner.
pub struct Scene {
    /// World-space positions (three per triangle, not shared) and triangles.
    mesh: MeshData,
    /// UV of each corner, `[t][k]`.
    uvs: Vec<[[f64; 2]; 3]>,
    /// Material of each triangle (index into `materials`).
    material: Vec<usize>,
    materials: Vec<Material>,
    /// The file's triangles as stored (as `simplify` counts them) and as drawn.
    instancing: Instancing,
}

fn floats(v: Option<&Value>) -> Option<Vec<f64>> {
    v?.as_array()?.iter().map(Value::as_f64).collect()
}

/// The bytes of image `i`: its buffer view, a `data:` URI or a file beside the glTF.
fn image_bytes(file: &GltfFile, i: usize, dir: Option<&Path>) -> Result<Vec<u8>> {
    let img = &file.json["images"][i];
    if let Some(v) = img.get("bufferView").and_then(Value::as_u64) {
        let view = &file.json["bufferViews"][v as usize];
        let buffer = view["buffer"].as_u64().unwrap_or(0) as usize;
        let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().unwrap_or(0) as usize;
        return file
            .buffers
            .get(buffer)
            .and_then(|b| b.get(offset..offset.checked_add(len)?))
            .map(<[u8]>::to_vec)
            .ok_or_else(|| anyhow!("image {i}: buffer view {v} lies outside its buffer"));
    }
    let uri = img["uri"]
        .as_str()
        .ok_or_else(|| anyhow!("image {i} has neither a bufferView nor a uri"))?;
    if let Some(rest) = uri.strip_prefix("data:") {
        let data = rest
            .split_once(";base64,")
            .ok_or_else(|| anyhow!("image {i}: a data URI that is not base64"))?
            .1;
        use base64::Engine as _;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .with_context(|| format!("image {i}: bad base64"));
    }
    let dir = dir.ok_or_else(|| anyhow!("image {i}: external file {uri} with no directory"))?;
    let path = dir.join(uri.replace("%20", " "));
    std::fs::read(&path).with_context(|| format!("image {i}: cannot read {}", path.display()))
}

fn materials(file: &GltfFile, dir: Option<&Path>) -> Vec<Material> {
    let Some(list) = file.json.get("materials").and_then(Value::as_array) else {
        return Vec::new();
    };
    list.iter()
        .map(|m| {
            let pbr = &m["pbrMetallicRoughness"];
            let factor = floats(pbr.get("baseColorFactor"))
                .filter(|f| f.len() == 4)
                .map_or([1.0; 4], |f| [f[0], f[1], f[2], f[3]]);
            let info = pbr.get("baseColorTexture");
            let tex_coord = info
                .and_then(|t| t.get("texCoord"))
                .and_then(Value::as_u64)
                .unwrap_or(0) as usize;
            let texture = info
                .and_then(|t| t.get("index"))
                .and_then(Value::as_u64)
                .and_then(|t| {
                    let tex = &file.json["textures"][t as usize];
                    let source = tex.get("source").and_then(Value::as_u64)?;
                    let bytes = image_bytes(file, source as usize, dir).ok()?;
                    let image = image::load_from_memory(&bytes).ok()?.to_rgba8();
                    let sampler = tex
                        .get("sampler")
                        .and_then(Value::as_u64)
                        .map(|s| &file.json["samplers"][s as usize]);
                    let wrap = ["wrapS", "wrapT"].map(|k| {
                        sampler
                            .and_then(|s| s.get(k))
                            .and_then(Value::as_u64)
                            .unwrap_or(10497)
                    });
                    Some(Texture { image, wrap })
                });
            Material {
                factor,
                texture,
                tex_coord,
            }
        })
        .collect()
}

impl Scene {
    /// Flattens `file`'s scene (see the module documentation). `dir` is where external images
    /// are looked up.
    pub fn new(file: &GltfFile, dir: Option<&Path>) -> Scene {
        let mut materials = materials(file, dir);
        let plain = materials.len();
        materials.push(Material {
            factor: NO_MATERIAL,
            texture: None,
            tex_coord: 0,
        });
        let mut scene = Scene {
            mesh: MeshData::default(),
            uvs: Vec::new(),
            material: Vec::new(),
            materials,
            instancing: Instancing::default(),
        };
        for pl in crate::io::gltf::placements(&file.json) {
            for p in file.primitives.iter().filter(|p| p.mesh == pl.mesh) {
                let material = file.json["meshes"][p.mesh]["primitives"][p.index]
                    .get("material")
                    .and_then(Value::as_u64)
                    .map_or(plain, |m| (m as usize).min(plain));
                scene.add(p, &pl.world, material);
            }
        }
        scene.instancing = crate::io::gltf::Instancing::of(file);
        scene
    }

    fn add(&mut self, p: &crate::io::gltf::Primitive, world: &Transform, material: usize) {
        let name = format!("TEXCOORD_{}", self.materials[material].tex_coord);
        let uv = p.attributes.iter().find(|s| s.semantic == name);
        let place = |v: [f32; 3]| -> [f32; 3] {
            let v = v.map(f64::from);
            [0, 1, 2].map(|r| {
                (world[r][0] * v[0] + world[r][1] * v[1] + world[r][2] * v[2] + world[r][3]) as f32
            })
        };
        for t in &p.triangles {
            let Some(corners) = t
                .iter()
                .map(|&i| p.positions.get(i as usize))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let base = self.mesh.positions.len() as u32;
            self.mesh
                .positions
                .extend(corners.iter().map(|&&v| place(v)));
            self.mesh.triangles.push([base, base + 1, base + 2]);
            self.uvs.push(t.map(|i| {
                uv.and_then(|s| crate::io::gltf::uv_of(s, i as usize))
                    .unwrap_or([0.0; 2])
            }));
            self.material.push(material);
        }
    }

    /// The flattened geometry (world space).
    pub fn mesh(&self) -> &MeshData {
        &self.mesh
    }

    /// "2856 triangles", or "2856 triangles, 3624 drawn: mesh 1 drawn 2 times" when the
    /// scene draws another number than the file stores.
    pub fn triangles_text(&self) -> String {
        let i = &self.instancing;
        if i.drawn == i.stored && i.meshes.is_empty() {
            format!("{} triangles", i.stored)
        } else {
            format!(
                "{} triangles, {} drawn: {}",
                i.stored,
                i.drawn,
                i.meshes_text()
            )
        }
    }
}

fn wrap(x: f64, mode: u64) -> f64 {
    match mode {
        33071 => x.clamp(0.0, 1.0),
        33648 => {
            let f = x.rem_euclid(2.0);
            if f > 1.0 {
                2.0 - f
            } else {
                f
            }
        }
        _ => x.rem_euclid(1.0),
    }
}

fn sample(t: &Texture, uv: [f64; 2]) -> [f64; 4] {
    let (w, h) = t.image.dimensions();
    if w == 0 || h == 0 {
        return [1.0; 4];
    }
    let x = wrap(uv[0], t.wrap[0]) * f64::from(w) - 0.5;
    let y = wrap(uv[1], t.wrap[1]) * f64::from(h) - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    // Neighbour texels past the edge: the opposite edge when repeating, the edge itself else.
    let index = |i: f64, n: u32, mode: u64| {
        let i = i as i64;
        if mode == 10497 {
            i.rem_euclid(i64::from(n)) as u32
        } else {
            i.clamp(0, i64::from(n) - 1) as u32
        }
    };
    let texel = |xi: f64, yi: f64| {
        let (xi, yi) = (index(xi, w, t.wrap[0]), index(yi, h, t.wrap[1]));
        t.image.get_pixel(xi, yi).0.map(|c| f64::from(c) / 255.0)
    };
    let (a, b, c, d) = (
        texel(x0, y0),
        texel(x0 + 1.0, y0),
        texel(x0, y0 + 1.0),
        texel(x0 + 1.0, y0 + 1.0),
    );
    [0, 1, 2, 3].map(|k| {
        (a[k] * (1.0 - fx) + b[k] * fx) * (1.0 - fy) + (c[k] * (1.0 - fx) + d[k] * fx) * fy
    })
}

/// Draws `scene` from `view` with its textures; with `edges`, each triangle's edges are drawn
/// over it (one pixel wide, depth-tested with their triangle).
pub fn render_textured(scene: &Scene, view: &View, edges: bool) -> RgbImage {
    let (w, h) = (SIZE as usize, SIZE as usize);
    let mut depth = vec![f64::INFINITY; w * h];
    let mut img = RgbImage::from_pixel(SIZE, SIZE, BACKGROUND);
    let mesh = &scene.mesh;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let p = tri.map(|i| mesh.positions[i as usize].map(f64::from));
        let e1 = [0, 1, 2].map(|k| p[1][k] - p[0][k]);
        let e2 = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let light = view.light();
        let lambert = if len > 0.0 {
            ((n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len).abs()
        } else {
            0.0
        };
        let shade = 0.35 + 0.65 * lambert;
        let s = p.map(|q| view.project(q));
        let area =
            (s[1][0] - s[0][0]) * (s[2][1] - s[0][1]) - (s[2][0] - s[0][0]) * (s[1][1] - s[0][1]);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        // Height of each corner over its opposite edge, in pixels (for the edge lines).
        let edge_len =
            |a: [f64; 3], b: [f64; 3]| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let heights = [
            area.abs() / edge_len(s[1], s[2]),
            area.abs() / edge_len(s[2], s[0]),
            area.abs() / edge_len(s[0], s[1]),
        ];
        let min = |k: usize| s.iter().map(|v| v[k]).fold(f64::INFINITY, f64::min);
        let max = |k: usize| s.iter().map(|v| v[k]).fold(f64::NEG_INFINITY, f64::max);
        let (x0, x1) = (min(0).floor().max(0.0), max(0).ceil().min(w as f64 - 1.0));
        let (y0, y1) = (min(1).floor().max(0.0), max(1).ceil().min(h as f64 - 1.0));
        if x1 < x0 || y1 < y0 {
            continue;
        }
        let m = &scene.materials[scene.material[t]];
        let uv = scene.uvs[t];
        for y in y0 as usize..=y1 as usize {
            for x in x0 as usize..=x1 as usize {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let e = |a: [f64; 3], b: [f64; 3]| {
                    (b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1])
                };
                let b = [e(s[1], s[2]) / area, e(s[2], s[0]) / area];
                let b = [b[0], b[1], 1.0 - b[0] - b[1]];
                if b.iter().any(|&c| c < 0.0) {
                    continue;
                }
                let z = b[0] * s[0][2] + b[1] * s[1][2] + b[2] * s[2][2];
                let slot = &mut depth[y * w + x];
                if z >= *slot {
                    continue;
                }
                *slot = z;
                let on_edge = edges && (0..3).any(|k| b[k] * heights[k] < 0.75);
                let colour = if on_edge {
                    EDGE
                } else {
                    let base = match &m.texture {
                        Some(tex) => {
                            let at =
                                [0, 1].map(|k| b[0] * uv[0][k] + b[1] * uv[1][k] + b[2] * uv[2][k]);
                            let c = sample(tex, at);
                            [0, 1, 2].map(|k| c[k] * m.factor[k])
                        }
                        None => [m.factor[0], m.factor[1], m.factor[2]],
                    };
                    base.map(|c| c * 255.0 * shade)
                };
                img.put_pixel(
                    x as u32,
                    y as u32,
                    Rgb(colour.map(|c| c.round().clamp(0.0, 255.0) as u8)),
                );
            }
        }
    }
    img
}

/// original | simplified | simplified with its edges, all from the original's view.
pub fn render_textured_compare(original: &Scene, simplified: &Scene) -> RgbImage {
    let view = View::fit(&original.mesh);
    let panels = [
        render_textured(original, &view, false),
        render_textured(simplified, &view, false),
        render_textured(simplified, &view, true),
    ];
    let mut out = RgbImage::from_pixel(3 * SIZE, SIZE, BACKGROUND);
    for (k, panel) in panels.iter().enumerate() {
        image::imageops::replace(&mut out, panel, i64::from(k as u32 * SIZE), 0);
    }
    for x in [SIZE, 2 * SIZE] {
        for y in 0..SIZE {
            out.put_pixel(x, y, Rgb([160, 160, 160]));
        }
    }
    out
}

fn load(path: &Path) -> Result<Scene> {
    let file = crate::io::gltf::load(path)?;
    Ok(Scene::new(&file, path.parent()))
}

/// `tinydecimate render` for glTF: `mesh` (or original | `mesh` | `mesh` with edges, with
/// `compare`) drawn with textures into the PNG `out`.
pub fn draw(mesh: &Path, out: &Path, compare: Option<&Path>) -> Result<()> {
    let m = load(mesh)?;
    let img = match compare {
        None => {
            crate::outln!("{}: {}", mesh.display(), m.triangles_text());
            render_textured(&m, &View::fit(&m.mesh), false)
        }
        Some(orig) => {
            if !crate::io::gltf::is_gltf_path(orig) {
                anyhow::bail!(
                    "{}: a glTF model is compared with a glTF original; {} is not one",
                    mesh.display(),
                    orig.display()
                );
            }
            let o = load(orig)?;
            crate::outln!(
                "panels: original ({}) | simplified ({}) | simplified with its edges",
                o.triangles_text(),
                m.triangles_text()
            );
            render_textured_compare(&o, &m)
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
    use base64::Engine as _;
    use serde_json::json;

    fn data_uri(mime: &str, bytes: &[u8]) -> String {
        format!(
            "data:{mime};base64,{}",
            base64::engine::general_purpose::STANDARD.encode(bytes)
        )
    }

    /// A unit quad in the z = 0 plane under one node with `node` as its transform, textured
    /// with a 2x1 image (red left, blue right) through UVs `u` per corner.
    fn quad(node: Value, u: [f32; 4]) -> GltfFile {
        let mut png = Vec::new();
        let mut img = RgbaImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgba([255, 0, 0, 255]));
        img.put_pixel(1, 0, image::Rgba([0, 0, 255, 255]));
        image::DynamicImage::ImageRgba8(img)
            .write_to(&mut std::io::Cursor::new(&mut png), ImageFormat::Png)
            .unwrap();
        let pos = [
            [0.0f32, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let mut bin: Vec<u8> = pos.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        for u in u {
            bin.extend_from_slice(&u.to_le_bytes());
            bin.extend_from_slice(&0.5f32.to_le_bytes());
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        let mut node = node;
        node["mesh"] = json!(0);
        let json = json!({
            "asset": {"version": "2.0"},
            "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [node],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                "indices": 2, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0, "sampler": 0}],
            "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
            "images": [{"uri": data_uri("image/png", &png)}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
            ],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 48},
                {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                {"buffer": 0, "byteOffset": 80, "byteLength": 12}
            ],
            "buffers": [{"byteLength": bin.len(), "uri": data_uri("application/octet-stream", &bin)}]
        });
        crate::io::gltf::parse(&serde_json::to_vec(&json).unwrap(), None).unwrap()
    }

    /// Colour of the drawn pixels: how many are mostly red and mostly blue.
    fn reds_and_blues(img: &RgbImage) -> (usize, usize) {
        let drawn = img.pixels().filter(|p| **p != BACKGROUND);
        drawn.fold((0, 0), |(r, b), p| {
            (
                r + usize::from(p[0] > 2 * p[2] + 20),
                b + usize::from(p[2] > 2 * p[0] + 20),
            )
        })
    }

    #[test]
    fn texture_follows_the_uvs() {
        // u from 0 (red texel) on the left to 1 (blue texel) on the right.
        let file = quad(json!({}), [0.0, 1.0, 1.0, 0.0]);
        let scene = Scene::new(&file, None);
        let view = View::fit(scene.mesh());
        let img = render_textured(&scene, &view, false);
        let (r, b) = reds_and_blues(&img);
        assert!(r > 1000 && b > 1000, "red {r} blue {b}");
        // The leftmost drawn pixel of the middle row is red; with u mirrored it is blue.
        let left = |img: &RgbImage| {
            (0..SIZE)
                .map(|x| *img.get_pixel(x, SIZE / 2))
                .find(|p| *p != BACKGROUND)
                .unwrap()
        };
        assert!(left(&img)[0] > 40 && left(&img)[2] == 0, "{:?}", left(&img));
        let mirrored = Scene::new(&quad(json!({}), [1.0, 0.0, 0.0, 1.0]), None);
        let img = render_textured(&mirrored, &view, false);
        assert!(left(&img)[2] > 40 && left(&img)[0] == 0, "{:?}", left(&img));
        // All red: u = 0 everywhere, clamped sampler.
        let red = Scene::new(&quad(json!({}), [-3.0, 0.0, 0.0, -1.0]), None);
        let (r, b) = reds_and_blues(&render_textured(&red, &view, false));
        assert!(r > 2000 && b == 0, "red {r} blue {b}");
    }

    #[test]
    fn node_transforms_place_the_mesh() {
        let plain = Scene::new(&quad(json!({}), [0.0, 1.0, 1.0, 0.0]), None);
        let node = json!({"translation": [10.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0],
                          "rotation": [0.0, 0.0, 0.70710677, 0.70710677]});
        let moved = Scene::new(&quad(node, [0.0, 1.0, 1.0, 0.0]), None);
        let (lo, hi) = moved.mesh().bbox().unwrap();
        // Scaled by 2, turned 90° about z (x -> y), then moved by 10 along x.
        let near = |a: f64, b: f64| (a - b).abs() < 1e-5;
        assert!(near(lo[0], 8.0) && near(hi[0], 10.0), "{lo:?} {hi:?}");
        assert!(near(lo[1], 0.0) && near(hi[1], 2.0), "{lo:?} {hi:?}");
        assert_eq!(moved.mesh().triangles.len(), plain.mesh().triangles.len());
        // A column-major matrix gives the same placement.
        let m = json!({"matrix": [0.0, 2.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0,
                                  10.0, 0.0, 0.0, 1.0]});
        let by_matrix = Scene::new(&quad(m, [0.0, 1.0, 1.0, 0.0]), None);
        let (lo2, hi2) = by_matrix.mesh().bbox().unwrap();
        assert!(
            (0..3).all(|k| near(lo[k], lo2[k]) && near(hi[k], hi2[k])),
            "{lo2:?} {hi2:?}"
        );
    }

    #[test]
    fn compare_has_three_panels_and_edges_in_the_third() {
        let s = Scene::new(&quad(json!({}), [0.0, 1.0, 1.0, 0.0]), None);
        let img = render_textured_compare(&s, &s);
        assert_eq!(img.dimensions(), (3 * SIZE, SIZE));
        let dark = |x0: u32| {
            (x0 + 1..x0 + SIZE)
                .flat_map(|x| (0..SIZE).map(move |y| (x, y)))
                .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 40))
                .count()
        };
        assert_eq!(dark(0), 0);
        assert!(dark(2 * SIZE) > 100, "{}", dark(2 * SIZE));
    }
}
