//! Packet traversal of the obvhs CWBVH for shadow rays that share one direction (all shadow rays
//! of one directional light): up to 64 rays, one bit each, walk the tree together.
//!
//! Per visited node the quantised child boxes are decoded once for the whole packet and each child
//! box is tested against many rays at once: 16 with AVX-512 where the CPU has it (detected at run
//! time), else 4 (SSE through glam's `Vec4`). Leaf triangles are then tested only for the rays
//! whose box tests reached them.
//!
//! The result is bit-identical to tracing each ray alone with obvhs's `ray_traverse_miss`
//! ([`crate::Tracer::occluded`] with `t_max = inf`): a ray's box tests use the same f32
//! operations in the same order as `CwBvhNode::intersect_ray` (the product of quantised plane and
//! scaled inverse direction, rounded, plus the ray's scaled origin offset, rounded; max/min with
//! the same operands; `t_min` clamped to obvhs's node epsilon), a ray reaches exactly the leaves
//! it would reach alone, and its triangles are tested with the same arithmetic as
//! `RtTriangle::intersect` (see the crate-private `packet_kernels` module). An any-hit query with a fixed `t_max`
//! does not depend on the traversal order, so the packet's order (front to back for the shared
//! direction) changes only the speed.

use glam::{Vec3, Vec3A};
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::rt_triangle::RtTriangle;

use crate::packet_kernels::{Kernel, Soa, SseKernel};

/// Most rays in one packet (one bit each of a `u64`).
pub const PACKET_SIZE: usize = 64;

/// Traversal stack size: obvhs keeps CWBVHs below depth 32 and a node pushes at most 8 children.
const STACK: usize = 8 * 32;

/// The packet's shared data: the rays (origins as SoA), the shared direction and its inverse.
pub(crate) struct Packet {
    /// Origins, structure of arrays.
    pub origin: Soa,
    /// The shared direction (no -0.0 components).
    pub dir: Vec3A,
    /// obvhs's safe inverse of `dir`.
    pub inv: Vec3A,
    /// Whether each direction component is negative (which quantised plane is entered first).
    pub neg: [bool; 3],
    /// Number of rays.
    pub len: usize,
}

/// Occlusion of up to [`PACKET_SIZE`] rays `origins[i] + t dir`, `t in [0, inf)`: bit `i` of the
/// result is set when ray `i` hits a triangle. `dir` must already have its -0.0 components turned
/// into +0.0 (see `tracer::positive_zeros`). `allow_avx512: false` forces the SSE kernels.
///
/// # Panics
/// If more than [`PACKET_SIZE`] origins are given.
pub(crate) fn occluded_packet(
    bvh: &CwBvh,
    tris: &[RtTriangle],
    dir: Vec3A,
    origins: &[Vec3],
    allow_avx512: bool,
) -> u64 {
    let n = origins.len();
    assert!(n <= PACKET_SIZE, "{n} rays in one packet, at most {PACKET_SIZE}");
    if n == 0 || bvh.nodes.is_empty() {
        return 0;
    }
    let proto = Ray::new(Vec3A::ZERO, dir, 0.0, f32::INFINITY);
    let mut packet = Packet {
        origin: Soa::default(),
        dir,
        inv: proto.inv_direction,
        neg: [dir.x < 0.0, dir.y < 0.0, dir.z < 0.0],
        len: n,
    };
    for (i, o) in origins.iter().enumerate() {
        for a in 0..3 {
            packet.origin.0[a][i] = o[a];
        }
    }
    #[cfg(target_arch = "x86_64")]
    if allow_avx512 && crate::packet_kernels::has_avx512() {
        // SAFETY: the CPU supports AVX-512F (checked just above).
        return unsafe { crate::packet_kernels::traverse_avx512(bvh, tris, &packet) };
    }
    let _ = allow_avx512;
    // SAFETY: the SSE kernels need only SSE2 (part of x86-64) or nothing (glam's scalar code).
    unsafe { traverse::<SseKernel>(bvh, tris, &packet) }
}

/// The packet traversal with box and triangle kernels `K`; returns the occluded rays' bits.
///
/// # Safety
/// The CPU must support `K`'s target features.
#[inline(always)]
pub(crate) unsafe fn traverse<K: Kernel>(bvh: &CwBvh, tris: &[RtTriangle], packet: &Packet) -> u64 {
    let n = packet.len;
    let all = if n == PACKET_SIZE { u64::MAX } else { (1u64 << n) - 1 };
    let octant =
        (u8::from(packet.neg[0]) << 2) | (u8::from(packet.neg[1]) << 1) | u8::from(packet.neg[2]);
    let mut alive = all; // rays not yet found occluded
    let mut scratch = Soa::default();
    let mut stack = [(0u32, 0u64); STACK];
    stack[0] = (0, all);
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let (index, mask) = stack[len];
        let active = mask & alive;
        if active == 0 {
            continue;
        }
        let node = &bvh.nodes[index as usize];
        // SAFETY: the caller vouches for K's target features.
        let hits = unsafe { K::node_hits(node, packet, active, &mut scratch) };
        // Internal children reached, with their traversal key (obvhs's order: ascending
        // slot ^ octant).
        let mut inner: [(u8, u32, u64); 8] = [(0, 0, 0); 8];
        let mut inner_len = 0;
        for (c, &rays) in hits.iter().enumerate() {
            if rays == 0 {
                continue;
            }
            let meta = node.child_meta[c];
            // Internal children have meta 001s_sss + 24 (bits 3 and 4 set), leaves never do.
            if meta & 0b1_1000 == 0b1_1000 {
                let slot = u32::from(meta & 0b1_1111) - 24;
                let child = node.child_base_idx
                    + (u32::from(node.imask) & !(u32::MAX << slot)).count_ones();
                inner[inner_len] = ((slot as u8) ^ octant, child, rays);
                inner_len += 1;
            } else {
                let first = node.primitive_base_idx + u32::from(meta & 0b1_1111);
                let count = (meta & 0b1110_0000).count_ones();
                for prim in first..first + count {
                    let todo = rays & alive;
                    if todo == 0 {
                        break;
                    }
                    // SAFETY: as above.
                    alive &= !unsafe { K::triangle_hits(&tris[prim as usize], packet, todo) };
                }
            }
        }
        if alive == 0 {
            break;
        }
        // Push so that the lowest key is popped first (insertion sort, descending).
        for i in 1..inner_len {
            let mut j = i;
            while j > 0 && inner[j - 1].0 < inner[j].0 {
                inner.swap(j - 1, j);
                j -= 1;
            }
        }
        for &(_, child, rays) in &inner[..inner_len] {
            stack[len] = (child, rays);
            len += 1;
        }
    }
    all & !alive
}
