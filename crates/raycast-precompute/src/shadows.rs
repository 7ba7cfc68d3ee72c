//! The shadow-ray stage of one view: for every (foreground pixel, light) pair with n.l > 0, does
//! the shadow ray from the pixel's shadow origin towards the light escape?
//!
//! Two equivalent ways (bit-identical results, tested):
//! * [`Traversal::Packets`] (the default): foreground pixels are grouped into 8 x 8 image tiles;
//!   per tile and light, the tile's front-facing pixels form one packet of parallel rays traced
//!   together ([`Tracer::occluded_packet`]). Tiles are processed in parallel, each with all its
//!   lights in turn (the BVH nodes near the tile stay in cache), and each tile writes its own
//!   visibility words, which are then copied into place.
//! * [`Traversal::OneByOne`]: the simple reference, each pair traced alone with
//!   [`Tracer::occluded`], pixels in parallel.

use crate::light::Light;
use glam::Vec3;
use rayon::prelude::*;

use crate::packet::PACKET_SIZE;
use crate::tracer::Tracer;
use crate::visibility::Visibility;

/// Side of the square image tiles whose pixels form one shadow-ray packet per light.
pub const TILE: u32 = 8;
const _: () = assert!((TILE * TILE) as usize <= PACKET_SIZE);

/// How the shadow rays of a view are traced; results are bit-identical.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Traversal {
    /// Per (8 x 8 tile, light) packets of parallel rays (fast).
    #[default]
    Packets,
    /// Every (pixel, light) ray alone (the simple reference).
    OneByOne,
}

/// Shadow rays of one view. `origins`, `normals` and `pixels` describe the foreground pixels
/// (shadow-ray origin, interpolated normal, row-major pixel index in an image `width` wide);
/// `lights` are validated (unit directions). Returns the visibility and the numbers of traced and skipped
/// (back-facing) pairs.
pub(crate) fn trace_shadows(
    tracer: &Tracer,
    origins: &[Vec3],
    normals: &[Vec3],
    pixels: &[u32],
    width: u32,
    lights: &[Light],
    traversal: Traversal,
) -> (Visibility, u64, u64) {
    let mut visibility = Visibility::new(origins.len(), lights.len());
    if lights.is_empty() || origins.is_empty() {
        return (visibility, 0, 0);
    }
    let (traced, skipped) = match traversal {
        Traversal::OneByOne => one_by_one(tracer, origins, normals, lights, &mut visibility),
        Traversal::Packets => {
            packets(tracer, origins, normals, pixels, width, lights, &mut visibility)
        }
    };
    (visibility, traced, skipped)
}

fn one_by_one(
    tracer: &Tracer,
    origins: &[Vec3],
    normals: &[Vec3],
    lights: &[Light],
    visibility: &mut Visibility,
) -> (u64, u64) {
    let wpp = Visibility::words_for(lights.len());
    visibility
        .lit
        .par_chunks_mut(wpp)
        .zip(visibility.front.par_chunks_mut(wpp))
        .zip(origins.par_iter().zip(normals))
        .map(|((lit, front), (origin, normal))| {
            let (mut traced, mut skip) = (0u64, 0u64);
            for (l, light) in lights.iter().enumerate() {
                let Some((dir, t_max)) = light.toward(*origin) else {
                    skip += 1;
                    continue;
                };
                if normal.dot(dir) <= 0.0 {
                    skip += 1;
                    continue;
                }
                traced += 1;
                front[l / 64] |= 1 << (l % 64);
                if !tracer.occluded(*origin, dir, t_max) {
                    lit[l / 64] |= 1 << (l % 64);
                }
            }
            (traced, skip)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// The foreground pixels (indices into `pixels`) grouped by tile, tiles in row-major order,
/// pixels row-major within a tile.
fn tiles(pixels: &[u32], width: u32) -> Vec<Vec<u32>> {
    let tiles_x = width.div_ceil(TILE);
    let tile_of = |p: u32| (p / width / TILE) * tiles_x + (p % width) / TILE;
    let mut order: Vec<u32> = (0..pixels.len() as u32).collect();
    order.sort_by_key(|&k| tile_of(pixels[k as usize])); // stable: row-major within a tile
    order
        .chunk_by(|&a, &b| tile_of(pixels[a as usize]) == tile_of(pixels[b as usize]))
        .map(<[u32]>::to_vec)
        .collect()
}

/// Row-major pixel indices (increasing) grouped into rows of `tile x tile` image tiles: one entry
/// per row of tiles, holding its non-empty tiles left to right, each tile's pixels row-major.
pub(crate) fn tile_rows(pixels: &[u32], width: u32, tile: u32) -> Vec<Vec<Vec<u32>>> {
    let mut rows: Vec<Vec<Vec<u32>>> = Vec::new();
    for band in pixels.chunk_by(|&a, &b| a / width / tile == b / width / tile) {
        let mut tiles: Vec<Vec<u32>> = Vec::new();
        let mut order = band.to_vec();
        order.sort_by_key(|&p| (p % width) / tile); // stable: row-major within a tile
        for t in order.chunk_by(|&a, &b| (a % width) / tile == (b % width) / tile) {
            tiles.push(t.to_vec());
        }
        rows.push(tiles);
    }
    rows
}

fn packets(
    tracer: &Tracer,
    origins: &[Vec3],
    normals: &[Vec3],
    pixels: &[u32],
    width: u32,
    lights: &[Light],
    visibility: &mut Visibility,
) -> (u64, u64) {
    let wpp = Visibility::words_for(lights.len());
    let tiles = tiles(pixels, width);
    // Per tile: its pixels' (lit, front) words, pixel-major like the visibility sets.
    let results: Vec<(Vec<u64>, Vec<u64>, u64)> = tiles
        .par_iter()
        .map(|members| {
            let m = members.len();
            let mut lit = vec![0u64; m * wpp];
            let mut front = vec![0u64; m * wpp];
            let mut traced = 0u64;
            let mut packet = [Vec3::ZERO; PACKET_SIZE];
            let mut slot = [0usize; PACKET_SIZE];
            for (l, light) in lights.iter().enumerate() {
                let (word, bit) = (l / 64, 1u64 << (l % 64));
                let Light::Directional(dir) = light else {
                    // A point light: a direction per pixel, each ray alone, ending at the light.
                    for (j, &h) in members.iter().enumerate() {
                        let origin = origins[h as usize];
                        let Some((d, t_max)) = light.toward(origin) else { continue };
                        if normals[h as usize].dot(d) > 0.0 {
                            front[j * wpp + word] |= bit;
                            traced += 1;
                            if !tracer.occluded(origin, d, t_max) {
                                lit[j * wpp + word] |= bit;
                            }
                        }
                    }
                    continue;
                };
                let mut k = 0;
                for (j, &h) in members.iter().enumerate() {
                    if normals[h as usize].dot(*dir) > 0.0 {
                        packet[k] = origins[h as usize];
                        slot[k] = j;
                        front[j * wpp + word] |= bit;
                        k += 1;
                    }
                }
                traced += k as u64;
                let occluded = tracer.occluded_packet(*dir, &packet[..k]);
                for (i, &j) in slot[..k].iter().enumerate() {
                    if occluded & (1u64 << i) == 0 {
                        lit[j * wpp + word] |= bit;
                    }
                }
            }
            (lit, front, traced)
        })
        .collect();
    let mut traced = 0;
    for (members, (lit, front, t)) in tiles.iter().zip(results) {
        traced += t;
        for (j, &h) in members.iter().enumerate() {
            let dst = h as usize * wpp..(h as usize + 1) * wpp;
            visibility.lit[dst.clone()].copy_from_slice(&lit[j * wpp..(j + 1) * wpp]);
            visibility.front[dst].copy_from_slice(&front[j * wpp..(j + 1) * wpp]);
        }
    }
    let pairs = (origins.len() * lights.len()) as u64;
    (traced, pairs - traced)
}
