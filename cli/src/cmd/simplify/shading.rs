//! Hard edges welded for the simplifier (`--hard-edges weld`, the default on inputs with
//! attributes).
//!
//! A renderer splits a vertex wherever any attribute jumps. Where only the normal (or tangent)
//! jumps, a hard edge or flat shading, the texture is continuous: the split is not a seam of
//! the texture, and a model shaded flat splits every vertex into one wedge per face. Handed to
//! the library as they are, such splits make every vertex a seam vertex with many wedges: the
//! seam rule then either locks them (meshoptimizer keeps 966 of flat-shaded Suzanne's 968
//! triangles) or lets a corner take a wedge from another texture chart.
//!
//! So the library gets one vertex per position *and* non-shading attributes (texture
//! coordinates, colours, joints, weights, morph target positions): each corner is renamed to
//! the first input vertex with its key. The seams it sees are then the texture's own. Each
//! corner of the result is mapped back to an input vertex of its key, so its attributes are
//! still an input vertex's, bit for bit: a triangle the run left as it was gets its own
//! corners back; any other corner takes, among the vertices of its key, the one whose normal
//! is closest to its triangle's normal (the side of the hard edge it lies on; the lowest index
//! on a tie).

use std::collections::HashMap;
use std::hash::Hash;

use crate::io::MeshData;

/// Vertices grouped by key, and their normals.
#[derive(Clone, Debug)]
pub struct Shading {
    /// Each vertex's representative: the first vertex with its key.
    rep: Vec<u32>,
    /// The vertices of each representative's key, ascending (empty for other vertices).
    members: Vec<Vec<u32>>,
    /// One normal per vertex, when the input has them.
    normals: Option<Vec<[f32; 3]>>,
}

impl Shading {
    /// Groups vertices `0..keys.len()` by `keys`.
    pub fn new<K: Hash + Eq>(keys: Vec<K>, normals: Option<Vec<[f32; 3]>>) -> Self {
        let mut first: HashMap<K, u32> = HashMap::with_capacity(keys.len());
        let mut rep = Vec::with_capacity(keys.len());
        let mut members = vec![Vec::new(); keys.len()];
        for (i, k) in keys.into_iter().enumerate() {
            let r = *first.entry(k).or_insert(i as u32);
            rep.push(r);
            members[r as usize].push(i as u32);
        }
        let normals = normals.filter(|n| n.len() == rep.len());
        Shading {
            rep,
            members,
            normals,
        }
    }

    /// Parts' groupings side by side, each part's vertices numbered after the previous
    /// part's (as [`super::textured`] joins the parts of one mesh): no key is shared across
    /// parts, so a vertex is only ever renamed within its own part (its own material).
    pub fn concat(parts: &[&Shading]) -> Shading {
        let mut out = Shading {
            rep: Vec::new(),
            members: Vec::new(),
            normals: parts.iter().all(|s| s.normals.is_some()).then(Vec::new),
        };
        for s in parts {
            let offset = out.rep.len() as u32;
            out.rep.extend(s.rep.iter().map(|&r| r + offset));
            out.members.extend(
                s.members
                    .iter()
                    .map(|m| m.iter().map(|&v| v + offset).collect()),
            );
            if let (Some(all), Some(n)) = (&mut out.normals, &s.normals) {
                all.extend_from_slice(n);
            }
        }
        out
    }

    /// Whether any two vertices share a key (otherwise there is nothing to weld).
    pub fn welds(&self) -> bool {
        self.rep.iter().enumerate().any(|(i, &r)| r as usize != i)
    }

    /// `mesh` with every corner renamed to its representative.
    pub fn keyed(&self, mesh: &MeshData) -> MeshData {
        MeshData {
            positions: mesh.positions.clone(),
            triangles: mesh
                .triangles
                .iter()
                .map(|t| t.map(|i| self.rep.get(i as usize).copied().unwrap_or(i)))
                .collect(),
        }
    }

    /// The result `out` (over representatives) in the input's vertices (see the module docs).
    pub fn restore(&self, mesh: &MeshData, out: &[[u32; 3]]) -> Vec<[u32; 3]> {
        // The input's triangles by their keyed corners, rotated to start at the smallest.
        let canon = |t: [u32; 3]| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        };
        let mut unchanged: HashMap<[u32; 3], [u32; 3]> = HashMap::new();
        for t in &mesh.triangles {
            let keyed = t.map(|i| self.rep.get(i as usize).copied().unwrap_or(i));
            let k = (0..3).min_by_key(|&k| keyed[k]).unwrap_or(0);
            unchanged
                .entry(canon(keyed))
                .or_insert([t[k], t[(k + 1) % 3], t[(k + 2) % 3]]);
        }
        out.iter()
            .map(|&t| {
                if let Some(&orig) = unchanged.get(&canon(t)) {
                    return orig;
                }
                let n = face_normal(&mesh.positions, t);
                t.map(|r| self.closest(r, n))
            })
            .collect()
    }

    /// Among representative `r`'s vertices, the one whose normal is closest to `n`.
    fn closest(&self, r: u32, n: [f64; 3]) -> u32 {
        let (Some(normals), Some(members)) = (&self.normals, self.members.get(r as usize)) else {
            return r;
        };
        let mut best = (f64::NEG_INFINITY, r);
        for &v in members {
            let m = normals[v as usize].map(f64::from);
            let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
            let dot = if len > 0.0 {
                (m[0] * n[0] + m[1] * n[1] + m[2] * n[2]) / len
            } else {
                -2.0
            };
            if dot > best.0 {
                best = (dot, v);
            }
        }
        best.1
    }
}

/// The unit normal of triangle `t` (zero when it has no area).
fn face_normal(p: &[[f32; 3]], t: [u32; 3]) -> [f64; 3] {
    let q = t.map(|i| {
        p.get(i as usize)
            .copied()
            .unwrap_or_default()
            .map(f64::from)
    });
    let (u, v) = (
        [q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]],
        [q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]],
    );
    let c = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    if len > 0.0 {
        c.map(|x| x / len)
    } else {
        [0.0; 3]
    }
}

/// Whether a glTF attribute only shades (its jumps are hard edges, not seams).
pub fn shades(semantic: &str) -> bool {
    semantic == "NORMAL" || semantic == "TANGENT"
}

/// A glTF primitive's keys (position and every non-shading attribute, morph targets included,
/// as bytes) and normals.
pub fn gltf(p: &crate::io::gltf::Primitive) -> Shading {
    let n = p.positions.len();
    let streams: Vec<&crate::io::gltf::Stream> = p
        .attributes
        .iter()
        .chain(p.targets.iter().flatten())
        .filter(|s| !shades(&s.semantic) && s.count() >= n)
        .collect();
    let keys = (0..n)
        .map(|i| {
            let mut k = Vec::new();
            for s in &streams {
                k.extend_from_slice(s.element(i));
            }
            k
        })
        .collect();
    let normals = p
        .attributes
        .iter()
        .find(|s| s.semantic == "NORMAL" && s.component_type == 5126 && s.elem == 12)
        .filter(|s| s.count() >= n)
        .map(|s| {
            (0..n)
                .map(|i| {
                    let e = s.element(i);
                    let f = |k: usize| f32::from_le_bytes([e[k], e[k + 1], e[k + 2], e[k + 3]]);
                    [f(0), f(4), f(8)]
                })
                .collect()
        });
    Shading::new(keys, normals)
}

/// An OBJ group's keys (position and texture coordinate indices) and normals.
pub fn obj(file: &crate::io::objattr::ObjFile, g: usize) -> Shading {
    let group = &file.groups[g];
    let keys = group.vertices.iter().map(|c| (c.0, c.1)).collect();
    let parse = |text: &str| {
        let mut it = text.split_whitespace().map(str::parse::<f32>);
        Some([it.next()?.ok()?, it.next()?.ok()?, it.next()?.ok()?])
    };
    let normals = group
        .vertices
        .iter()
        .map(|c| {
            c.2.and_then(|n| file.vn_text.get(n as usize))
                .and_then(|t| parse(t))
        })
        .collect::<Option<Vec<_>>>();
    Shading::new(keys, normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two faces of a cube edge shaded flat: each position has two vertices (one normal per
    /// face) and one texture coordinate.
    fn hinge() -> (MeshData, Shading) {
        let p = |x: f32, y: f32, z: f32| [x, y, z];
        // Face z = 0 (normal +z): vertices 0-3; face x = 1 (normal +x): vertices 4-7, where 4
        // and 5 sit on 1 and 2.
        let positions = vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(1.0, 1.0, -1.0),
            p(1.0, 0.0, -1.0),
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3], [4, 7, 6], [4, 6, 5]];
        let normals = vec![
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
        ];
        let keys = positions.iter().map(|q| q.map(f32::to_bits)).collect();
        (
            MeshData {
                positions,
                triangles,
            },
            Shading::new(keys, Some(normals)),
        )
    }

    #[test]
    fn hard_edges_weld_and_come_back() {
        let (mesh, s) = hinge();
        assert!(s.welds());
        let keyed = s.keyed(&mesh);
        // The x = 1 face now uses the z = 0 face's vertices 1 and 2.
        assert_eq!(keyed.triangles[2], [1, 7, 6]);
        assert_eq!(keyed.triangles[3], [1, 6, 2]);
        // Unchanged triangles get their own corners back, whatever their rotation.
        let back = s.restore(&mesh, &[[7, 6, 1], [0, 1, 2]]);
        assert_eq!(back, vec![[4, 7, 6], [0, 1, 2]]);
        // A new triangle on the x = 1 side takes the vertices with normal +x.
        let back = s.restore(&mesh, &[[1, 7, 2]]);
        assert_eq!(back, vec![[4, 7, 5]]);
        // One on the z = 0 side keeps the +z ones.
        let back = s.restore(&mesh, &[[3, 1, 2]]);
        assert_eq!(back, vec![[3, 1, 2]]);
    }

    #[test]
    fn distinct_keys_weld_nothing() {
        let s = Shading::new(vec![1, 2, 3], None);
        assert!(!s.welds());
    }
}
