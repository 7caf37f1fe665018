//! Meshes for the firmware examples, computed at compile time so that they are plain `static`s
//! in flash.

#![no_std]

/// A saddle `z = x² − y²` over a 16 × 16 grid of quads on `[-0.5, 0.5]²`: 289 vertices,
/// 512 triangles.
pub mod saddle {
    /// Quads per side.
    pub const N: usize = 16;
    /// Vertices.
    pub const VERTICES: usize = (N + 1) * (N + 1);
    /// Triangles.
    pub const TRIANGLES: usize = 2 * N * N;

    /// The positions, row by row.
    pub const fn positions() -> [[f32; 3]; VERTICES] {
        let mut p = [[0.0f32; 3]; VERTICES];
        let mut i = 0;
        while i < VERTICES {
            let x = (i % (N + 1)) as f32 / N as f32 - 0.5;
            let y = (i / (N + 1)) as f32 / N as f32 - 0.5;
            p[i] = [x, y, x * x - y * y];
            i += 1;
        }
        p
    }

    /// Two triangles per quad, wound counter-clockwise seen from +z.
    pub const fn triangles() -> [[u16; 3]; TRIANGLES] {
        let mut t = [[0u16; 3]; TRIANGLES];
        let mut q = 0;
        while q < N * N {
            let v = ((q / N) * (N + 1) + q % N) as u16;
            let row = (N + 1) as u16;
            t[2 * q] = [v, v + 1, v + row + 1];
            t[2 * q + 1] = [v, v + row + 1, v + row];
            q += 1;
        }
        t
    }
}
