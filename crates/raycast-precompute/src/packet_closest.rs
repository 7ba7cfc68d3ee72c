//! Closest-hit packet traversal for camera rays (AVX-512 only; elsewhere the camera rays are
//! traced one by one): up to 64 rays of one direction octant walk the CWBVH together, each with
//! its own direction and shrinking `t_max`, 16 rays per vector.
//!
//! Bit-identical to obvhs's single-ray `ray_traverse` (hit triangle and `t`, ties included):
//! obvhs visits nodes depth first, testing a node's child boxes with the ray's current `t_max`,
//! then the node's leaf primitives in descending bit order, then the internal children in
//! descending priority (`slot ^ (7 - octant)`). The packet visits nodes in exactly this order
//! (rays share the octant, so the priority order), and a ray takes part in a node only where its
//! own box test passed, so every ray sees its own single-ray sequence of box and triangle tests,
//! done with the same f32 operations (see the crate-private `packet_kernels` module).

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::rt_triangle::RtTriangle;

use crate::packet::PACKET_SIZE;
use crate::packet_kernels::avx512::{cross_d_c, dot, load};
use crate::packet_kernels::{NODE_EPSILON, Soa};

/// Traversal stack size (as in [`crate::packet`]).
const STACK: usize = 8 * 32;

/// Closest hits of up to 64 rays (all with the same octant: the signs of their direction
/// components agree, -0.0 already turned into +0.0): per ray, `(leaf-order primitive index,
/// t)`, or `(u32::MAX, t_max)` for a miss.
///
/// # Safety
/// The CPU must support AVX-512F.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn closest_packet(
    bvh: &CwBvh,
    tris: &[RtTriangle],
    rays: &[Ray],
) -> [(u32, f32); PACKET_SIZE] {
    let n = rays.len();
    assert!(n <= PACKET_SIZE && n > 0);
    let neg = [rays[0].direction.x < 0.0, rays[0].direction.y < 0.0, rays[0].direction.z < 0.0];
    debug_assert!(rays.iter().all(|r| [
        r.direction.x < 0.0,
        r.direction.y < 0.0,
        r.direction.z < 0.0
    ] == neg));
    let oct_inv = 7 - ((u8::from(neg[0]) << 2) | (u8::from(neg[1]) << 1) | u8::from(neg[2]));
    let (mut org, mut dir, mut inv) = (Soa::default(), Soa::default(), Soa::default());
    let mut tmax = [f32::INFINITY; PACKET_SIZE];
    let mut prim = [u32::MAX; PACKET_SIZE];
    for (i, r) in rays.iter().enumerate() {
        for a in 0..3 {
            org.0[a][i] = r.origin[a];
            dir.0[a][i] = r.direction[a];
            inv.0[a][i] = r.inv_direction[a];
        }
        tmax[i] = r.tmax;
    }
    let groups = n.div_ceil(16);
    let all = if n == PACKET_SIZE { u64::MAX } else { (1u64 << n) - 1 };
    let mut stack = [(0u32, 0u64); STACK];
    stack[0] = (0, all);
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let (index, active) = stack[len];
        let node = &bvh.nodes[index as usize];
        let extent = node.compute_extent();
        // Quantised near/far planes per child and axis (as f32).
        let mut planes = [[[0f32; 2]; 3]; 8];
        let q = [
            (&node.child_min_x, &node.child_max_x),
            (&node.child_min_y, &node.child_max_y),
            (&node.child_min_z, &node.child_max_z),
        ];
        for (c, pl) in planes.iter_mut().enumerate() {
            for a in 0..3 {
                let (lo, hi) = (q[a].0[c], q[a].1[c]);
                let (near, far) = if neg[a] { (hi, lo) } else { (lo, hi) };
                pl[a] = [near as f32, far as f32];
            }
        }
        let mut child_rays = [0u64; 8];
        for g in 0..groups {
            if (active >> (16 * g)) & 0xffff == 0 {
                continue;
            }
            // obvhs: adjusted_ray_dir_inv = extent * inv_dir; adjusted_ray_origin = (p - o) * inv.
            let mut adj_inv = [_mm512_setzero_ps(); 3];
            let mut adj_org = [_mm512_setzero_ps(); 3];
            for a in 0..3 {
                let inv_a = load(&inv.0[a], g);
                adj_inv[a] = _mm512_mul_ps(_mm512_set1_ps(extent[a]), inv_a);
                let diff = _mm512_sub_ps(_mm512_set1_ps(node.p[a]), load(&org.0[a], g));
                adj_org[a] = _mm512_mul_ps(diff, inv_a);
            }
            let ray_tmax = load(&tmax, g);
            let eps = _mm512_set1_ps(NODE_EPSILON);
            for (c, rays_c) in child_rays.iter_mut().enumerate() {
                if node.child_meta[c] == 0 {
                    continue;
                }
                let mut t = [[_mm512_setzero_ps(); 2]; 3];
                for a in 0..3 {
                    for k in 0..2 {
                        let plane = _mm512_set1_ps(planes[c][a][k]);
                        t[a][k] = _mm512_add_ps(_mm512_mul_ps(plane, adj_inv[a]), adj_org[a]);
                    }
                }
                let tmin = _mm512_max_ps(t[0][0], _mm512_max_ps(t[1][0], t[2][0]));
                let tmin = _mm512_max_ps(tmin, eps);
                let tmax_c = _mm512_min_ps(t[0][1], _mm512_min_ps(t[1][1], t[2][1]));
                let tmax_c = _mm512_min_ps(tmax_c, ray_tmax);
                let m = _mm512_cmp_ps_mask::<_CMP_LE_OS>(tmin, tmax_c);
                *rays_c |= u64::from(m) << (16 * g);
            }
        }
        // Leaf children in descending primitive-bit order, internal ones by priority.
        let mut leaves: [(u8, u8, u64); 8] = [(0, 0, 0); 8];
        let mut inner: [(u8, u32, u64); 8] = [(0, 0, 0); 8];
        let (mut n_leaves, mut n_inner) = (0, 0);
        for (c, &rays_c) in child_rays.iter().enumerate() {
            let rays_c = rays_c & active;
            let meta = node.child_meta[c];
            if rays_c == 0 {
                continue;
            }
            if meta & 0b1_1000 == 0b1_1000 {
                let slot = u32::from(meta & 0b1_1111) - 24;
                let child = node.child_base_idx
                    + (u32::from(node.imask) & !(u32::MAX << slot)).count_ones();
                inner[n_inner] = ((slot as u8) ^ oct_inv, child, rays_c);
                n_inner += 1;
            } else {
                leaves[n_leaves] =
                    (meta & 0b1_1111, (meta & 0b1110_0000).count_ones() as u8, rays_c);
                n_leaves += 1;
            }
        }
        sort_desc(&mut leaves[..n_leaves], |l| l.0);
        for &(offset, count, rays_c) in &leaves[..n_leaves] {
            for k in (0..count).rev() {
                let id = node.primitive_base_idx + u32::from(offset + k);
                let tri = &tris[id as usize];
                triangle(tri, id, rays_c, groups, &org, &dir, &mut tmax, &mut prim);
            }
        }
        // Highest priority popped first: push in ascending priority.
        sort_desc(&mut inner[..n_inner], |c| c.0);
        for &(_, child, rays_c) in inner[..n_inner].iter().rev() {
            stack[len] = (child, rays_c);
            len += 1;
        }
    }
    let mut out = [(u32::MAX, f32::INFINITY); PACKET_SIZE];
    for i in 0..n {
        out[i] = (prim[i], tmax[i]);
    }
    out
}

/// Insertion sort, descending by `key` (at most 8 entries).
#[inline(always)]
fn sort_desc<T: Copy>(items: &mut [T], key: impl Fn(&T) -> u8) {
    for i in 1..items.len() {
        let mut j = i;
        while j > 0 && key(&items[j - 1]) < key(&items[j]) {
            items.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// `RtTriangle::intersect` for the rays of `rays`; a hit at `0 <= t < t_max` becomes the ray's
/// closest hit (obvhs: `if t < traverse_ray.tmax`).
#[allow(clippy::too_many_arguments)]
#[inline]
#[target_feature(enable = "avx512f")]
fn triangle(
    tri: &RtTriangle,
    id: u32,
    rays: u64,
    groups: usize,
    org: &Soa,
    dir: &Soa,
    tmax: &mut [f32; PACKET_SIZE],
    prim: &mut [u32; PACKET_SIZE],
) {
    for g in 0..groups {
        let m = ((rays >> (16 * g)) & 0xffff) as u16;
        if m == 0 {
            continue;
        }
        let (dx, dy, dz) = (load(&dir.0[0], g), load(&dir.0[1], g), load(&dir.0[2], g));
        let cx = _mm512_sub_ps(_mm512_set1_ps(tri.v0.x), load(&org.0[0], g));
        let cy = _mm512_sub_ps(_mm512_set1_ps(tri.v0.y), load(&org.0[1], g));
        let cz = _mm512_sub_ps(_mm512_set1_ps(tri.v0.z), load(&org.0[2], g));
        let (rx, ry, rz) = cross_d_c(dx, dy, dz, cx, cy, cz);
        let inv_det = _mm512_div_ps(_mm512_set1_ps(1.0), dot(dx, dy, dz, tri.ng));
        let u = _mm512_mul_ps(dot(rx, ry, rz, tri.e2), inv_det);
        let v = _mm512_mul_ps(dot(rx, ry, rz, tri.e1), inv_det);
        let w = _mm512_sub_ps(_mm512_sub_ps(_mm512_set1_ps(1.0), u), v);
        let bits = _mm512_or_si512(
            _mm512_or_si512(_mm512_castps_si512(u), _mm512_castps_si512(v)),
            _mm512_castps_si512(w),
        );
        let inside = _mm512_cmpge_epi32_mask(bits, _mm512_setzero_si512())
            & _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(inv_det, _mm512_setzero_ps());
        let t = _mm512_mul_ps(dot(cx, cy, cz, tri.ng), inv_det);
        let old = load(tmax, g);
        let ok = m
            & inside
            & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(t, _mm512_setzero_ps())
            & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, old);
        if ok == 0 {
            continue;
        }
        let lanes = &mut tmax[16 * g..16 * g + 16];
        // SAFETY: 16 writable f32s.
        unsafe { _mm512_storeu_ps(lanes.as_mut_ptr(), _mm512_mask_mov_ps(old, ok, t)) };
        for i in 0..16 {
            if ok & (1 << i) != 0 {
                prim[16 * g + i] = id;
            }
        }
    }
}
