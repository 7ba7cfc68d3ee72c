//! Packet traversal of the obvhs CWBVH for shadow rays that share one direction (all shadow rays
//! of one directional light): up to 64 rays, one bit each, walk the tree together.
//!
//! Per visited node the quantised child boxes are decoded once for the whole packet and each child
//! box is tested against 4 rays at a time (SSE through glam's `Vec4`); leaf triangles are then
//! tested, one by one, only for the rays whose box tests reached them.
//!
//! The result is bit-identical to tracing each ray alone with obvhs's `ray_traverse_miss`
//! ([`crate::Tracer::occluded`] with `t_max = inf`): a ray's box tests use the same f32
//! operations in the same order as `CwBvhNode::intersect_ray` (the product of quantised plane and
//! scaled inverse direction, rounded, plus the ray's scaled origin offset, rounded; max/min in the
//! same argument order; `t_min` clamped to obvhs's node epsilon), a ray reaches exactly the leaves
//! it would reach alone, and its triangles are tested with the same `RtTriangle::intersect` on
//! the same `Ray`. An any-hit query with a fixed `t_max` does not depend on the traversal order,
//! so the packet's order (front to back for the shared direction) changes only the speed.

use glam::{Vec3, Vec3A, Vec4};
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::rt_triangle::RtTriangle;

/// Most rays in one packet (one bit each of a `u64`).
pub const PACKET_SIZE: usize = 64;

/// obvhs 0.4's `cwbvh::node::EPSILON` (crate-private there): node box tests clamp the ray's
/// entry distance to at least this.
const NODE_EPSILON: f32 = 0.0001;

/// Groups of 4 rays in a full packet.
const GROUPS: usize = PACKET_SIZE / 4;

/// Traversal stack size: obvhs keeps CWBVHs below depth 32 and a node pushes at most 8 children.
const STACK: usize = 8 * 32;

/// Occlusion of up to [`PACKET_SIZE`] rays `origins[i] + t dir`, `t in [0, inf)`: bit `i` of the
/// result is set when ray `i` hits a triangle. `dir` must already have its -0.0 components turned
/// into +0.0 (see `tracer::positive_zeros`).
///
/// # Panics
/// If more than [`PACKET_SIZE`] origins are given.
pub(crate) fn occluded_packet(bvh: &CwBvh, tris: &[RtTriangle], dir: Vec3A, origins: &[Vec3]) -> u64 {
    let n = origins.len();
    assert!(n <= PACKET_SIZE, "{n} rays in one packet, at most {PACKET_SIZE}");
    if n == 0 || bvh.nodes.is_empty() {
        return 0;
    }
    let proto = Ray::new(Vec3A::ZERO, dir, 0.0, f32::INFINITY);
    let inv = proto.inv_direction;
    let inv4 = [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)];
    let ray_tmax = Vec4::splat(proto.tmax);
    let eps = Vec4::splat(NODE_EPSILON);
    let neg = [dir.x < 0.0, dir.y < 0.0, dir.z < 0.0];
    let octant = (u8::from(neg[0]) << 2) | (u8::from(neg[1]) << 1) | u8::from(neg[2]);

    // The rays (for the triangle tests) and their origins as 4-ray groups (for the box tests).
    let mut rays = [proto; PACKET_SIZE];
    let mut org = [[Vec4::ZERO; 3]; GROUPS];
    for (i, o) in origins.iter().enumerate() {
        rays[i].origin = Vec3A::from(*o);
        org[i / 4][0][i % 4] = o.x;
        org[i / 4][1][i % 4] = o.y;
        org[i / 4][2][i % 4] = o.z;
    }
    let groups = n.div_ceil(4);
    let all = if n == PACKET_SIZE { u64::MAX } else { (1u64 << n) - 1 };
    let mut alive = all; // rays not yet found occluded

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
        // obvhs: adjusted_ray_dir_inv = extent * inv_dir; adjusted_ray_origin = (p - o) * inv_dir.
        let adj_inv = node.compute_extent() * inv;
        let p = Vec3A::from(node.p);
        let mut adj_org = [[Vec4::ZERO; 3]; GROUPS];
        for g in 0..groups {
            if (active >> (4 * g)) & 0xf != 0 {
                for a in 0..3 {
                    adj_org[g][a] = (Vec4::splat(p[a]) - org[g][a]) * inv4[a];
                }
            }
        }
        // Internal children reached, with their traversal key (obvhs's order: ascending
        // slot ^ octant).
        let mut inner: [(u8, u32, u64); 8] = [(0, 0, 0); 8];
        let mut inner_len = 0;
        for c in 0..8 {
            let meta = node.child_meta[c];
            if meta == 0 {
                continue; // empty slot
            }
            let q = |lo: &[u8; 8], hi: &[u8; 8], a: usize| {
                let (near, far) = if neg[a] { (hi[c], lo[c]) } else { (lo[c], hi[c]) };
                (near as f32 * adj_inv[a], far as f32 * adj_inv[a])
            };
            let (x0, x1) = q(&node.child_min_x, &node.child_max_x, 0);
            let (y0, y1) = q(&node.child_min_y, &node.child_max_y, 1);
            let (z0, z1) = q(&node.child_min_z, &node.child_max_z, 2);
            let (x0, x1) = (Vec4::splat(x0), Vec4::splat(x1));
            let (y0, y1) = (Vec4::splat(y0), Vec4::splat(y1));
            let (z0, z1) = (Vec4::splat(z0), Vec4::splat(z1));
            let mut hits = 0u64;
            for g in 0..groups {
                if (active >> (4 * g)) & 0xf == 0 {
                    continue;
                }
                let [ox, oy, oz] = adj_org[g];
                let tmin = (x0 + ox).max((y0 + oy).max(z0 + oz)).max(eps);
                let tmax = (x1 + ox).min((y1 + oy).min(z1 + oz)).min(ray_tmax);
                hits |= u64::from(tmin.cmple(tmax).bitmask()) << (4 * g);
            }
            hits &= active;
            if hits == 0 {
                continue;
            }
            // Internal children have meta 001s_sss + 24 (bits 3 and 4 set), leaves never do.
            if meta & 0b1_1000 == 0b1_1000 {
                let slot = u32::from(meta & 0b1_1111) - 24;
                let child = node.child_base_idx
                    + (u32::from(node.imask) & !(u32::MAX << slot)).count_ones();
                inner[inner_len] = ((slot as u8) ^ octant, child, hits);
                inner_len += 1;
            } else {
                let first = node.primitive_base_idx + u32::from(meta & 0b1_1111);
                let count = (meta & 0b1110_0000).count_ones();
                for prim in first..first + count {
                    let tri = &tris[prim as usize];
                    let mut todo = hits & alive;
                    while todo != 0 {
                        let i = todo.trailing_zeros() as usize;
                        todo &= todo - 1;
                        if tri.intersect(&rays[i]) < proto.tmax {
                            alive &= !(1u64 << i);
                        }
                    }
                }
                if active & alive == 0 {
                    break;
                }
            }
        }
        if alive == 0 {
            break;
        }
        // Push so that the lowest key is popped first.
        let inner = &mut inner[..inner_len];
        inner.sort_unstable_by(|a, b| b.0.cmp(&a.0));
        for &(_, child, hits) in inner.iter() {
            stack[len] = (child, hits);
            len += 1;
        }
    }
    all & !alive
}
