//! Stanford PLY through ply-rs-bw: ASCII and binary (little and big endian). Reads the `vertex`
//! element's `x`, `y`, `z` (any numeric type) and the `face` element's `vertex_indices` (or
//! `vertex_index`) list; other elements and properties are ignored.

use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::{FanBuilder, ParseResult, Parsed};

/// Parses PLY bytes, see the module documentation.
pub(super) fn parse(bytes: &[u8]) -> ParseResult {
    let parser = Parser::<DefaultElement>::new();
    let ply = parser.read_ply(&mut std::io::BufReader::new(bytes)).map_err(|e| e.to_string())?;
    let vertices = ply.payload.get("vertex").ok_or("no `vertex` element")?;
    let faces = ply.payload.get("face").ok_or("no `face` element")?;

    let mut positions = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let mut p = [0.0f32; 3];
        for (k, name) in ["x", "y", "z"].iter().enumerate() {
            p[k] = v
                .get(*name)
                .and_then(scalar)
                .ok_or_else(|| format!("vertex {i} has no numeric `{name}` property"))?;
        }
        positions.push(Vec3::from_array(p));
    }

    let mut fans = FanBuilder::new(positions.len());
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .ok_or_else(|| format!("face {i} has no `vertex_indices` list"))?;
        let pushed = match list {
            Property::ListChar(l) => fans.push(l.iter().map(|&x| i64::from(x))),
            Property::ListUChar(l) => fans.push(l.iter().map(|&x| i64::from(x))),
            Property::ListShort(l) => fans.push(l.iter().map(|&x| i64::from(x))),
            Property::ListUShort(l) => fans.push(l.iter().map(|&x| i64::from(x))),
            Property::ListInt(l) => fans.push(l.iter().map(|&x| i64::from(x))),
            Property::ListUInt(l) => fans.push(l.iter().map(|&x| i64::from(x))),
            _ => return Err(format!("face {i}: `vertex_indices` is not an integer list")),
        };
        if let Err(fault) = pushed {
            return Ok(Err(fault));
        }
    }
    Ok(Ok(Parsed {
        file_vertices: positions.len(),
        positions,
        triangles: fans.triangles,
        file_faces: fans.faces,
        polygon_faces: fans.polygons,
    }))
}

/// A scalar property as f32 (lists are not scalars).
fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Char(x) => f32::from(x),
        Property::UChar(x) => f32::from(x),
        Property::Short(x) => f32::from(x),
        Property::UShort(x) => f32::from(x),
        Property::Int(x) => x as f32,
        Property::UInt(x) => x as f32,
        Property::Float(x) => x,
        Property::Double(x) => x as f32,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_quad_and_triangle() {
        let ply = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\n\
            property float y\nproperty double z\nelement face 2\n\
            property list uchar int vertex_indices\nend_header\n\
            0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 1 2 3\n3 0 1 4\n";
        let p = parse(ply.as_bytes()).unwrap().unwrap();
        assert_eq!(p.positions.len(), 5);
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
        assert_eq!((p.file_faces, p.polygon_faces), (2, 1));
    }

    #[test]
    fn negative_index_is_a_fault_and_truncation_an_error() {
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 1\n\
            property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n";
        assert!(parse(ply.as_bytes()).unwrap().is_err());
        let cut = &ply.as_bytes()[..ply.len() - 12];
        assert!(parse(cut).is_err());
        assert!(parse(b"not a ply file").is_err());
    }
}
