//! meshoptimizer, the reference of `host-sim bench`: `meshopt::simplify` (and its
//! position-moving variant) with the scratch memory it allocates counted, and
//! `simplifySloppy` for the clustering table.

use std::sync::Mutex;
use std::time::{Duration, Instant};

use crate::io::MeshData;

/// Counts the bytes meshoptimizer holds in its temporary allocator (`meshopt_setAllocator`).
mod counted {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::ffi::c_void;
    use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
    use std::sync::Once;

    /// Bytes before each block holding its size (16 keeps the C++ alignment guarantee).
    const HEADER: usize = 16;
    static LIVE: AtomicUsize = AtomicUsize::new(0);
    static PEAK: AtomicUsize = AtomicUsize::new(0);

    unsafe extern "C" fn allocate(size: usize) -> *mut c_void {
        let Some(layout) = size
            .checked_add(HEADER)
            .and_then(|n| Layout::from_size_align(n, HEADER).ok())
        else {
            return std::ptr::null_mut();
        };
        // SAFETY: `layout` has a non-zero size.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            return p.cast();
        }
        // SAFETY: the block is at least HEADER bytes and 16-aligned.
        unsafe { p.cast::<usize>().write(size) };
        let live = LIVE.fetch_add(size, Relaxed) + size;
        PEAK.fetch_max(live, Relaxed);
        // SAFETY: within the block.
        unsafe { p.add(HEADER).cast() }
    }

    unsafe extern "C" fn deallocate(ptr: *mut c_void) {
        if ptr.is_null() {
            return;
        }
        // SAFETY: `ptr` came from `allocate`, so its block starts HEADER bytes before it, with
        // the size written there, and was allocated with this layout.
        unsafe {
            let p = ptr.cast::<u8>().sub(HEADER);
            let size = p.cast::<usize>().read();
            LIVE.fetch_sub(size, Relaxed);
            System.dealloc(p, Layout::from_size_align_unchecked(size + HEADER, HEADER));
        }
    }

    /// Runs `f` (which calls meshoptimizer; the caller serialises such calls) and returns the
    /// peak of the bytes meshoptimizer had allocated at once during it.
    pub fn peak_during<R>(f: impl FnOnce() -> R) -> (R, usize) {
        static INSTALL: Once = Once::new();
        // SAFETY: done once, before any other meshopt call of this process (every one goes
        // through here, under the caller's lock).
        INSTALL.call_once(|| unsafe {
            meshopt::ffi::meshopt_setAllocator(Some(allocate), Some(deallocate))
        });
        let base = LIVE.load(Relaxed);
        PEAK.store(base, Relaxed);
        let r = f();
        (r, PEAK.load(Relaxed) - base)
    }
}

/// meshoptimizer is not to be called concurrently while its allocator is (re)set, and the
/// counters are global: one call at a time.
static MESHOPT: Mutex<()> = Mutex::new(());

/// `meshopt::simplify` on `mesh` down to `target_triangles`: result, wall time of the call and
/// peak scratch bytes.
pub fn meshopt_simplify(mesh: &MeshData, target_triangles: usize) -> (MeshData, Duration, usize) {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let bytes = meshopt::utilities::typed_to_bytes(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<[f32; 3]>(), 0)
        .expect("12-byte vertices");
    let _lock = MESHOPT.lock().unwrap_or_else(|p| p.into_inner());
    let ((out, elapsed), peak) = counted::peak_during(|| {
        let start = Instant::now();
        let out = meshopt::simplify(
            &indices,
            &adapter,
            3 * target_triangles,
            1.0,
            meshopt::SimplifyOptions::None,
            None,
        );
        (out, start.elapsed())
    });
    let triangles = out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let result = MeshData {
        positions: mesh.positions.clone(),
        triangles,
    };
    (result, elapsed, peak)
}

/// `meshopt::simplify_with_attributes_and_locks` (no vertex locked) on `mesh` down to
/// `target_triangles`, with `attributes` (one row of `N` floats per vertex) weighted by
/// `weights`: the triangles (the positions are not moved).
pub fn meshopt_simplify_with_attributes<const N: usize>(
    mesh: &MeshData,
    target_triangles: usize,
    attributes: &[[f32; N]],
    weights: &[f32; N],
) -> MeshData {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let bytes = meshopt::utilities::typed_to_bytes(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<[f32; 3]>(), 0)
        .expect("12-byte vertices");
    let flat: Vec<f32> = attributes.iter().flatten().copied().collect();
    let locks = vec![false; mesh.positions.len()];
    assert_eq!(
        attributes.len(),
        mesh.positions.len(),
        "one attribute row per vertex"
    );
    let _lock = MESHOPT.lock().unwrap_or_else(|p| p.into_inner());
    let out = meshopt::simplify_with_attributes_and_locks(
        &indices,
        &adapter,
        &flat,
        weights,
        std::mem::size_of::<[f32; N]>(),
        &locks,
        3 * target_triangles,
        1.0,
        meshopt::SimplifyOptions::None,
        None,
    );
    MeshData {
        positions: mesh.positions.clone(),
        triangles: out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    }
}

/// `meshopt::simplify_with_update` (positions only, no attributes) on `mesh` down to
/// `target_triangles`: result (with the moved positions), wall time and peak scratch bytes.
pub fn meshopt_simplify_with_update(
    mesh: &MeshData,
    target_triangles: usize,
) -> (MeshData, Duration, usize) {
    let mut indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut positions = mesh.positions.clone();
    let _lock = MESHOPT.lock().unwrap_or_else(|p| p.into_inner());
    let ((n, elapsed), peak) = counted::peak_during(|| {
        let start = Instant::now();
        let n = meshopt::simplify_with_update(
            &mut indices,
            &mut positions,
            &mut [],
            &[],
            0,
            None,
            3 * target_triangles,
            1.0,
            meshopt::SimplifyOptions::None,
            None,
        );
        (n, start.elapsed())
    });
    indices.truncate(n);
    let triangles = indices
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let result = MeshData {
        positions,
        triangles,
    };
    (result, elapsed, peak)
}

/// `meshopt::simplify_sloppy` on `mesh` to `target` triangles (target error 1.0: no limit).
pub fn sloppy(mesh: &MeshData, target: usize) -> (MeshData, Duration) {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let bytes = meshopt::utilities::typed_to_bytes(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<[f32; 3]>(), 0)
        .expect("12-byte vertices");
    let start = Instant::now();
    let out = meshopt::simplify_sloppy(&indices, &adapter, 3 * target, 1.0, None);
    let dt = start.elapsed();
    (
        MeshData {
            positions: mesh.positions.clone(),
            triangles: out.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        },
        dt,
    )
}
