//! The box and triangle kernels of the packet traversal ([`crate::packet`]): SSE (4 rays per
//! vector, through glam, any x86-64 and a scalar fallback elsewhere) and AVX-512 (16 rays per
//! vector, chosen at run time).
//!
//! Bit-identity with obvhs's single-ray code rests on doing exactly its f32 operations, operand
//! for operand: node tests as `CwBvhNode::intersect_ray_simd` (no fused multiply-add there), and
//! triangle tests as `RtTriangle::intersect` with glam's `Vec3A` `cross` (fused only where glam
//! itself is compiled with FMA) and `dot` (`(x + y) + z`, unfused).

use glam::{Vec3A, Vec4};
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::Ray;
use obvhs::rt_triangle::RtTriangle;

use crate::packet::{PACKET_SIZE, Packet};

/// obvhs 0.4's `cwbvh::node::EPSILON` (crate-private there): node box tests clamp the ray's
/// entry distance to at least this.
pub(crate) const NODE_EPSILON: f32 = 0.0001;

/// Three coordinates of [`PACKET_SIZE`] rays, structure of arrays, 64-byte aligned.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct Soa(pub [[f32; PACKET_SIZE]; 3]);

impl Default for Soa {
    fn default() -> Self {
        Soa([[0.0; PACKET_SIZE]; 3])
    }
}

/// Per-node and per-triangle tests of a packet.
pub(crate) trait Kernel {
    /// The rays of `active` whose box test passes, per child slot (0 for empty slots).
    ///
    /// # Safety
    /// The CPU must support the kernel's target features.
    unsafe fn node_hits(
        node: &CwBvhNode,
        packet: &Packet,
        active: u64,
        scratch: &mut Soa,
    ) -> [u64; 8];

    /// The rays of `rays` that hit `tri` with `t in [0, inf)`.
    ///
    /// # Safety
    /// The CPU must support the kernel's target features.
    unsafe fn triangle_hits(tri: &RtTriangle, packet: &Packet, rays: u64) -> u64;
}

/// The near and far quantised planes of child `c` along each axis, times the node's scaled
/// inverse direction (obvhs's `x_min * adjusted_ray_dir_inv`, rounded once).
#[inline(always)]
fn child_planes(node: &CwBvhNode, c: usize, adj_inv: Vec3A, neg: [bool; 3]) -> [[f32; 2]; 3] {
    let planes = [
        (&node.child_min_x, &node.child_max_x),
        (&node.child_min_y, &node.child_max_y),
        (&node.child_min_z, &node.child_max_z),
    ];
    let mut out = [[0.0; 2]; 3];
    for a in 0..3 {
        let (lo, hi) = (planes[a].0[c], planes[a].1[c]);
        let (near, far) = if neg[a] { (hi, lo) } else { (lo, hi) };
        out[a] = [near as f32 * adj_inv[a], far as f32 * adj_inv[a]];
    }
    out
}

/// SSE kernels (glam `Vec4`); triangles one ray at a time with obvhs's own test.
pub(crate) struct SseKernel;

impl Kernel for SseKernel {
    #[inline(always)]
    unsafe fn node_hits(
        node: &CwBvhNode,
        packet: &Packet,
        active: u64,
        scratch: &mut Soa,
    ) -> [u64; 8] {
        let groups = packet.len.div_ceil(4);
        // obvhs: adjusted_ray_dir_inv = extent * inv_dir; adjusted_ray_origin = (p - o) * inv_dir.
        let adj_inv = node.compute_extent() * packet.inv;
        let p = Vec3A::from(node.p);
        for g in 0..groups {
            if (active >> (4 * g)) & 0xf != 0 {
                for a in 0..3 {
                    let o = Vec4::from_slice(&packet.origin.0[a][4 * g..]);
                    let adj = (Vec4::splat(p[a]) - o) * Vec4::splat(packet.inv[a]);
                    adj.write_to_slice(&mut scratch.0[a][4 * g..]);
                }
            }
        }
        let (eps, ray_tmax) = (Vec4::splat(NODE_EPSILON), Vec4::splat(f32::INFINITY));
        let mut out = [0u64; 8];
        for (c, out) in out.iter_mut().enumerate() {
            if node.child_meta[c] == 0 {
                continue; // empty slot
            }
            let [[x0, x1], [y0, y1], [z0, z1]] =
                child_planes(node, c, adj_inv, packet.neg).map(|a| a.map(Vec4::splat));
            let mut hits = 0u64;
            for g in 0..groups {
                if (active >> (4 * g)) & 0xf == 0 {
                    continue;
                }
                let ox = Vec4::from_slice(&scratch.0[0][4 * g..]);
                let oy = Vec4::from_slice(&scratch.0[1][4 * g..]);
                let oz = Vec4::from_slice(&scratch.0[2][4 * g..]);
                let tmin = (x0 + ox).max((y0 + oy).max(z0 + oz)).max(eps);
                let tmax = (x1 + ox).min((y1 + oy).min(z1 + oz)).min(ray_tmax);
                hits |= u64::from(tmin.cmple(tmax).bitmask()) << (4 * g);
            }
            *out = hits & active;
        }
        out
    }

    #[inline(always)]
    unsafe fn triangle_hits(tri: &RtTriangle, packet: &Packet, rays: u64) -> u64 {
        let mut hits = 0;
        let mut todo = rays;
        while todo != 0 {
            let i = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            // The ray as obvhs's Ray::new(origin, dir, 0, inf) builds it.
            let [x, y, z] = &packet.origin.0;
            let ray = Ray {
                origin: Vec3A::new(x[i], y[i], z[i]),
                direction: packet.dir,
                inv_direction: packet.inv,
                tmin: 0.0,
                tmax: f32::INFINITY,
            };
            // obvhs's ray_traverse_miss counts a hit when intersect(..) < ray.tmax.
            if tri.intersect(&ray) < f32::INFINITY {
                hits |= 1u64 << i;
            }
        }
        hits
    }
}

/// Whether the CPU has AVX-512F (cached by std).
#[cfg(target_arch = "x86_64")]
pub(crate) fn has_avx512() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
}

/// [`crate::packet::traverse`] with the AVX-512 kernels.
///
/// # Safety
/// The CPU must support AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn traverse_avx512(
    bvh: &obvhs::cwbvh::CwBvh,
    tris: &[RtTriangle],
    packet: &Packet,
) -> u64 {
    // SAFETY: the caller vouches for AVX-512F.
    unsafe { crate::packet::traverse::<avx512::Avx512Kernel>(bvh, tris, packet) }
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512 {
    use std::arch::x86_64::*;

    use glam::Vec3A;
    use obvhs::cwbvh::node::CwBvhNode;
    use obvhs::rt_triangle::RtTriangle;

    use super::{Kernel, NODE_EPSILON, Soa, child_planes};
    use crate::packet::Packet;

    /// AVX-512 kernels: 16 rays per vector.
    pub(crate) struct Avx512Kernel;

    /// The 16 lanes of group `g` of one SoA row.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn load(row: &[f32; 64], g: usize) -> __m512 {
        let lanes: &[f32; 16] = row[16 * g..16 * g + 16].try_into().expect("16 lanes");
        // SAFETY: `lanes` is 16 readable f32s.
        unsafe { _mm512_loadu_ps(lanes.as_ptr()) }
    }

    impl Kernel for Avx512Kernel {
        #[inline]
        #[target_feature(enable = "avx512f")]
        unsafe fn node_hits(
            node: &CwBvhNode,
            packet: &Packet,
            active: u64,
            scratch: &mut Soa,
        ) -> [u64; 8] {
            let groups = packet.len.div_ceil(16);
            let adj_inv = node.compute_extent() * packet.inv;
            let p = Vec3A::from(node.p);
            for g in 0..groups {
                if (active >> (16 * g)) & 0xffff != 0 {
                    for a in 0..3 {
                        let o = load(&packet.origin.0[a], g);
                        let diff = _mm512_sub_ps(_mm512_set1_ps(p[a]), o);
                        let adj = _mm512_mul_ps(diff, _mm512_set1_ps(packet.inv[a]));
                        let dst: &mut [f32; 16] =
                            (&mut scratch.0[a][16 * g..16 * g + 16]).try_into().expect("16");
                        // SAFETY: `dst` is 16 writable f32s.
                        unsafe { _mm512_storeu_ps(dst.as_mut_ptr(), adj) };
                    }
                }
            }
            let eps = _mm512_set1_ps(NODE_EPSILON);
            let ray_tmax = _mm512_set1_ps(f32::INFINITY);
            let mut out = [0u64; 8];
            for (c, out) in out.iter_mut().enumerate() {
                if node.child_meta[c] == 0 {
                    continue;
                }
                let [[x0, x1], [y0, y1], [z0, z1]] = child_planes(node, c, adj_inv, packet.neg);
                let (x0, x1) = (_mm512_set1_ps(x0), _mm512_set1_ps(x1));
                let (y0, y1) = (_mm512_set1_ps(y0), _mm512_set1_ps(y1));
                let (z0, z1) = (_mm512_set1_ps(z0), _mm512_set1_ps(z1));
                let mut hits = 0u64;
                for g in 0..groups {
                    if (active >> (16 * g)) & 0xffff == 0 {
                        continue;
                    }
                    let ox = load(&scratch.0[0], g);
                    let oy = load(&scratch.0[1], g);
                    let oz = load(&scratch.0[2], g);
                    let tmin = _mm512_max_ps(
                        _mm512_add_ps(x0, ox),
                        _mm512_max_ps(_mm512_add_ps(y0, oy), _mm512_add_ps(z0, oz)),
                    );
                    let tmin = _mm512_max_ps(tmin, eps);
                    let tmax = _mm512_min_ps(
                        _mm512_add_ps(x1, ox),
                        _mm512_min_ps(_mm512_add_ps(y1, oy), _mm512_add_ps(z1, oz)),
                    );
                    let tmax = _mm512_min_ps(tmax, ray_tmax);
                    let m = _mm512_cmp_ps_mask::<_CMP_LE_OS>(tmin, tmax);
                    hits |= u64::from(m) << (16 * g);
                }
                *out = hits & active;
            }
            out
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        unsafe fn triangle_hits(tri: &RtTriangle, packet: &Packet, rays: u64) -> u64 {
            let d = packet.dir;
            // As RtTriangle::intersect: inv_det = 1 / ng.d (shared by the packet).
            let inv_det = 1.0 / tri.ng.dot(d);
            if inv_det == 0.0 {
                return 0;
            }
            let (dx, dy, dz) = (_mm512_set1_ps(d.x), _mm512_set1_ps(d.y), _mm512_set1_ps(d.z));
            let inv = _mm512_set1_ps(inv_det);
            let zero = _mm512_setzero_ps();
            let mut hits = 0u64;
            for g in 0..packet.len.div_ceil(16) {
                if (rays >> (16 * g)) & 0xffff == 0 {
                    continue;
                }
                // c = v0 - origin
                let cx = _mm512_sub_ps(_mm512_set1_ps(tri.v0.x), load(&packet.origin.0[0], g));
                let cy = _mm512_sub_ps(_mm512_set1_ps(tri.v0.y), load(&packet.origin.0[1], g));
                let cz = _mm512_sub_ps(_mm512_set1_ps(tri.v0.z), load(&packet.origin.0[2], g));
                // r = d x c as glam computes it: (d.zxy * c - c.zxy * d).zxy
                let (rx, ry, rz) = cross_d_c(dx, dy, dz, cx, cy, cz);
                let u = _mm512_mul_ps(dot(rx, ry, rz, tri.e2), inv);
                let v = _mm512_mul_ps(dot(rx, ry, rz, tri.e1), inv);
                let w = _mm512_sub_ps(_mm512_sub_ps(_mm512_set1_ps(1.0), u), v);
                let bits = _mm512_or_si512(
                    _mm512_or_si512(_mm512_castps_si512(u), _mm512_castps_si512(v)),
                    _mm512_castps_si512(w),
                );
                let inside = _mm512_cmpge_epi32_mask(bits, _mm512_setzero_si512());
                // t = ng.c * inv_det, counted when t in [t_min = 0, t_max = inf] and < inf.
                let ng = tri.ng;
                let ngx = _mm512_mul_ps(_mm512_set1_ps(ng.x), cx);
                let ngy = _mm512_mul_ps(_mm512_set1_ps(ng.y), cy);
                let ngz = _mm512_mul_ps(_mm512_set1_ps(ng.z), cz);
                let t = _mm512_mul_ps(_mm512_add_ps(_mm512_add_ps(ngx, ngy), ngz), inv);
                let front = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(t, zero)
                    & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, _mm512_set1_ps(f32::INFINITY));
                hits |= u64::from(inside & front) << (16 * g);
            }
            hits & rays
        }
    }

    /// a.b per lane for a fixed b, rounded as glam's `Vec3A::dot`: (x + y) + z, products rounded.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn dot(ax: __m512, ay: __m512, az: __m512, b: Vec3A) -> __m512 {
        let xy = _mm512_add_ps(
            _mm512_mul_ps(ax, _mm512_set1_ps(b.x)),
            _mm512_mul_ps(ay, _mm512_set1_ps(b.y)),
        );
        _mm512_add_ps(xy, _mm512_mul_ps(az, _mm512_set1_ps(b.z)))
    }

    /// d x c component-wise, rounded as glam's `Vec3A::cross` (SSE2 build): each component is
    /// `a * b - c * d` with both products rounded, or fused as glam does when built with FMA.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub(crate) fn cross_d_c(
        dx: __m512,
        dy: __m512,
        dz: __m512,
        cx: __m512,
        cy: __m512,
        cz: __m512,
    ) -> (__m512, __m512, __m512) {
        // glam: sub = d.zxy * c - c.zxy * d, result = sub.zxy, so
        // x = d.y c.z - c.y d.z, y = d.z c.x - c.z d.x, z = d.x c.y - c.x d.y.
        (mul_sub(dy, cz, cy, dz), mul_sub(dz, cx, cz, dx), mul_sub(dx, cy, cx, dy))
    }

    /// a b - c d, rounded as glam's cross product does it.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn mul_sub(a: __m512, b: __m512, c: __m512, d: __m512) -> __m512 {
        #[cfg(not(target_feature = "fma"))]
        return _mm512_sub_ps(_mm512_mul_ps(a, b), _mm512_mul_ps(c, d));
        #[cfg(target_feature = "fma")]
        return _mm512_fnmadd_ps(c, d, _mm512_mul_ps(a, b));
    }
}
