//! The harness's working memory: one [`HostWorkspace`] (the library's `Storage` sized to the
//! mesh, used by every command and the golden reference), and the byte counts a right-sized
//! workspace, control links and stored quadrics need on a device.

use tinydecimate::cost::VertexQuadric;
use tinydecimate::{Storage, Workspace};

use crate::io::MeshData;

/// The harness's working memory: the library's [`Storage`] with `u32` links, sized to the mesh
/// (any mesh that fits in the PC's memory).
pub struct HostWorkspace {
    links: Vec<u32>,
    corners: Vec<[u32; 3]>,
    keys: Vec<f32>,
    flags: Vec<u8>,
}

impl HostWorkspace {
    /// Room for `vertices` positions and `triangles` triangles.
    pub fn new(vertices: usize, triangles: usize) -> Self {
        HostWorkspace {
            links: vec![0; 3 * vertices],
            corners: vec![[0; 3]; triangles],
            keys: vec![0.0; vertices],
            flags: vec![0; vertices],
        }
    }

    /// Room for `mesh`.
    pub fn for_mesh(mesh: &MeshData) -> Self {
        Self::new(mesh.positions.len(), mesh.triangles.len())
    }

    /// The library's view of it.
    pub fn storage(&mut self) -> Storage<'_, u32> {
        // The lengths agree by construction.
        Storage::new(
            &mut self.links,
            &mut self.corners,
            &mut self.keys,
            &mut self.flags,
        )
        .expect("HostWorkspace slices agree")
    }

    /// Its size in bytes.
    pub fn bytes(&self) -> usize {
        Storage::<u32>::bytes(self.keys.len(), self.corners.len())
    }
}

/// Bytes of `tinydecimate::Workspace` per vertex and per triangle for link type `L`, read
/// off the library's own `BYTES` (differences, so no fixed part or padding leaks in).
pub const fn element_bytes<L: tinydecimate::Index>() -> (usize, usize) {
    const P: usize = 1024;
    let v = (Workspace::<L, { 2 * P }, 0>::BYTES - Workspace::<L, P, 0>::BYTES) / P;
    let t = (Workspace::<L, 0, { 2 * P }>::BYTES - Workspace::<L, 0, P>::BYTES) / P;
    (v, t)
}

/// Bytes a workspace sized exactly for `v` vertices and `t` triangles needs, and its link size
/// `L` in bytes: `u16` links (L = 2) when `v <= 65535 && t <= 65535`, else `u32` (L = 4).
///
/// The per-vertex and per-triangle costs are taken from the library's `Workspace::BYTES`
/// instead of being hard-coded, so this stays exact when the workspace changes: today (3 links
/// per vertex: list head, heap slot, heap position; a 4-byte key and a flag byte; 3 links per
/// triangle) it is `v·(3L + 4 + 1) + t·3L`, rounded up to the struct's 4-byte alignment.
pub fn workspace_bytes(v: usize, t: usize) -> (usize, usize) {
    // The library's links number vertices and triangles below the link type's NIL.
    let small = v <= 65_535 && t <= 65_535;
    let ((pv, pt), link) = if small {
        (element_bytes::<u16>(), 2)
    } else {
        (element_bytes::<u32>(), 4)
    };
    let fixed = if small {
        Workspace::<u16, 0, 0>::BYTES
    } else {
        Workspace::<u32, 0, 0>::BYTES
    };
    ((fixed + v * pv + t * pt).next_multiple_of(4), link)
}

/// Bytes of control links per input triangle for a bounded run with `u16`/`u32` links:
/// `control_len(T, V)` links.
pub fn control_bytes(v: usize, t: usize) -> (usize, usize) {
    let n = tinydecimate::bound::control_len(t, v);
    (2 * n, 4 * n)
}

/// Bytes of stored quadrics per vertex.
pub const QUADRIC_BYTES: usize = core::mem::size_of::<VertexQuadric>();

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workspace_bytes_formula() {
        // Exactly the library's size for a right-sized workspace.
        assert_eq!(
            workspace_bytes(100, 200),
            (Workspace::<u16, 100, 200>::BYTES, 2)
        );
        assert_eq!(
            workspace_bytes(101, 7),
            (Workspace::<u16, 101, 7>::BYTES, 2)
        );
        assert_eq!(
            workspace_bytes(70_000, 9),
            (Workspace::<u32, 70_000, 9>::BYTES, 4)
        );
        // The per-element costs the lead's formula names: 3 corner links per triangle, a
        // 4-byte key and a flag byte plus some links per vertex.
        let (v16, t16) = element_bytes::<u16>();
        let (v32, t32) = element_bytes::<u32>();
        assert_eq!((t16, t32), (6, 12));
        assert_eq!((v16 - 5) % 2, 0);
        assert_eq!((v32 - 5) / 4, (v16 - 5) / 2);
        // u16 limits: 65 535 vertices, 65 535 triangles.
        assert_eq!(workspace_bytes(65_535, 65_535).1, 2);
        assert_eq!(workspace_bytes(65_536, 10).1, 4);
        assert_eq!(workspace_bytes(10, 65_536).1, 4);
    }
}
