//! Wavefront OBJ through tobj. Only positions and faces are read (normals, texture coordinates
//! and materials are ignored; `mtllib` files are not opened). Points and lines are skipped.
//!
//! tobj numbers each object's vertices afresh and drops vertices its faces do not use. To keep
//! the mesh connected across `o`/`g` groups, a vertex of a later group whose coordinates are
//! bit-identical to one of an earlier group is taken to be the same file vertex. The number of
//! `v` lines is counted separately, so vertices tobj dropped are still reported as unreferenced.
//! Vertices come in tobj's numbering (first use by a face), not in file order; vertex numbers in
//! error messages refer to that numbering, which is why they also print the coordinates.

use std::collections::HashMap;

use glam::Vec3;

use super::{FanBuilder, ParseResult, Parsed};

/// Parses OBJ bytes, see the module documentation.
pub(super) fn parse(bytes: &[u8]) -> ParseResult {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) =
        tobj::load_obj_buf(&mut std::io::BufReader::new(bytes), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| format!("{e} (tobj)"))?;

    let mut positions: Vec<Vec3> = Vec::new();
    let mut earlier: HashMap<[u32; 3], u32> = HashMap::new();
    let mut corners: Vec<Vec<u32>> = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let local: Vec<Vec3> = mesh.positions.chunks_exact(3).map(Vec3::from_slice).collect();
        let first_new = positions.len();
        let mut map: Vec<u32> = Vec::with_capacity(local.len());
        for p in &local {
            let global = match earlier.get(&p.to_array().map(f32::to_bits)) {
                Some(&g) => g,
                None => {
                    positions.push(*p);
                    (positions.len() - 1) as u32
                }
            };
            map.push(global);
        }
        // Only now may this model's vertices be matched, and only by later models.
        for (k, p) in positions.iter().enumerate().skip(first_new) {
            earlier.entry(p.to_array().map(f32::to_bits)).or_insert(k as u32);
        }
        let mut start = 0;
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        for arity in arities {
            let Some(face) = mesh.indices.get(start..start + arity) else {
                return Err("face list shorter than its arities (tobj)".into());
            };
            let mut global = Vec::with_capacity(arity);
            for &i in face {
                match map.get(i as usize) {
                    Some(&g) => global.push(g),
                    None => return Err(format!("face vertex {i} out of bounds (tobj)")),
                }
            }
            corners.push(global);
            start += arity;
        }
    }

    let mut fans = FanBuilder::new(positions.len());
    for face in &corners {
        if let Err(fault) = fans.push(face.iter().map(|&i| i64::from(i))) {
            return Ok(Err(fault));
        }
    }
    Ok(Ok(Parsed {
        positions,
        triangles: fans.triangles,
        file_vertices: count_vertex_lines(bytes),
        file_faces: fans.faces,
        polygon_faces: fans.polygons,
    }))
}

/// Number of `v` (position) lines in an OBJ file.
fn count_vertex_lines(bytes: &[u8]) -> usize {
    bytes
        .split(|&b| b == b'\n')
        .filter(|line| {
            let line = line.trim_ascii_start();
            line.len() > 1 && line[0] == b'v' && line[1].is_ascii_whitespace()
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_groups_and_unused_vertices() {
        let obj = b"# two groups sharing an edge, one quad, one unused vertex\n\
            v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nv 2 0 0\n\
            vn 0 0 1\n\
            o first\nf 1//1 2//1 3//1 4//1\n\
            o second\nf 2 6 3\nl 1 2\n";
        let p = parse(obj).unwrap().unwrap();
        assert_eq!(p.file_vertices, 6);
        assert_eq!((p.file_faces, p.polygon_faces), (2, 1));
        assert_eq!(p.positions.len(), 5, "shared vertices welded, unused one dropped");
        assert_eq!(p.triangles.len(), 3);
        // The second group's triangle uses the first group's vertices 2 and 3 (indices 1, 2).
        let last = p.triangles[2];
        assert_eq!(p.positions[last[0] as usize], Vec3::X);
        assert_eq!(p.positions[last[2] as usize], Vec3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn out_of_range_and_garbage() {
        let e = parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap_err();
        assert!(e.contains("out of bounds"), "{e}");
        // NaN parses (Rust's float parser accepts it); validation catches it later.
        let p = parse(b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap().unwrap();
        assert!(p.positions[0].x.is_nan());
        assert!(parse(b"v 1 x 0\n").is_err());
    }
}
