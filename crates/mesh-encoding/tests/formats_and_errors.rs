//! Every format on tiny fixtures written by the test (PLY ASCII and binary little endian, glTF
//! with a data-URI buffer, glTF with an external buffer, GLB), agreement between them, and bad
//! input: each fault gives an error that names the file and the fault, never a panic.

mod common;

use std::path::{Path, PathBuf};

use base64::Engine;
use mesh_encoding::{Error, LoadOptions, MeshFormat, TriMesh, load_mesh};

/// A tetrahedron: (positions, faces), outward counter-clockwise faces.
const TETRA_P: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
const TETRA_F: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn ply_header(format: &str, vertices: usize, faces: usize) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment fixture\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\nelement face {faces}\n\
         property list uchar int vertex_indices\nend_header\n"
    )
}

fn ply_ascii(p: &[[f32; 3]], f: &[Vec<i64>]) -> Vec<u8> {
    let mut s = ply_header("ascii", p.len(), f.len());
    for v in p {
        s += &format!("{} {} {}\n", v[0], v[1], v[2]);
    }
    for face in f {
        s += &format!("{}", face.len());
        for i in face {
            s += &format!(" {i}");
        }
        s += "\n";
    }
    s.into_bytes()
}

fn ply_binary(p: &[[f32; 3]], f: &[Vec<i64>]) -> Vec<u8> {
    let mut b = ply_header("binary_little_endian", p.len(), f.len()).into_bytes();
    for v in p {
        for c in v {
            b.extend(c.to_le_bytes());
        }
    }
    for face in f {
        b.push(face.len() as u8);
        for &i in face {
            b.extend((i as i32).to_le_bytes());
        }
    }
    b
}

fn tetra_faces() -> Vec<Vec<i64>> {
    TETRA_F.iter().map(|t| t.iter().map(|&i| i64::from(i)).collect()).collect()
}

/// The tetrahedron's binary buffer (f32 positions, then u16 indices) and its glTF JSON with the
/// given buffer URI (None: GLB binary chunk). The node translates by +2 in x.
fn gltf_parts(uri: Option<&str>) -> (Vec<u8>, String) {
    let mut bin = Vec::new();
    for v in TETRA_P {
        for c in v {
            bin.extend(c.to_le_bytes());
        }
    }
    for t in TETRA_F {
        for i in t {
            bin.extend((i as u16).to_le_bytes());
        }
    }
    let uri = uri.map(|u| format!(r#","uri":"{u}""#)).unwrap_or_default();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0,"translation":[2,0,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":{len}{uri}}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},
                       {{"buffer":0,"byteOffset":48,"byteLength":24}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3",
                       "min":[0,0,0],"max":[1,1,1]}},
                     {{"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}}]}}"#,
        len = bin.len()
    );
    (bin, json)
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(0x004E_4942u32.to_le_bytes());
    out.extend(b);
    out
}

fn expected(offset_x: f32) -> TriMesh {
    let positions = TETRA_P.iter().map(|p| glam::Vec3::from_array(*p) + offset_x * glam::Vec3::X);
    TriMesh::new(positions.collect(), TETRA_F.to_vec()).unwrap()
}

/// The triangles as coordinate triples, each rotated to start at its smallest corner (keeping the
/// orientation), sorted: equal for meshes that differ only in vertex numbering.
fn canonical(m: &TriMesh) -> Vec<[[u32; 3]; 3]> {
    let mut tris: Vec<[[u32; 3]; 3]> = (0..m.triangle_count())
        .map(|t| {
            let c = m.corners(t).map(|p| p.to_array().map(f32::to_bits));
            let k = (0..3).min_by_key(|&k| c[k]).unwrap();
            [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
        })
        .collect();
    tris.sort_unstable();
    tris
}

#[test]
fn every_format_gives_the_same_tetrahedron() {
    let tmp = common::TempDir::new("formats");
    let dir = tmp.0.clone();
    let (bin, json_ext) = gltf_parts(Some("tetra.bin"));
    write(&dir, "tetra.bin", &bin);
    let data_uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    let (_, json_data) = gltf_parts(Some(&data_uri));
    let (_, json_glb) = gltf_parts(None);
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let cases: Vec<(PathBuf, MeshFormat, f32)> = vec![
        (write(&dir, "t.obj", obj.as_bytes()), MeshFormat::Obj, 0.0),
        (write(&dir, "a.ply", &ply_ascii(&TETRA_P, &tetra_faces())), MeshFormat::Ply, 0.0),
        (write(&dir, "b.ply", &ply_binary(&TETRA_P, &tetra_faces())), MeshFormat::Ply, 0.0),
        (write(&dir, "ext.gltf", json_ext.as_bytes()), MeshFormat::Gltf, 2.0),
        (write(&dir, "uri.gltf", json_data.as_bytes()), MeshFormat::Gltf, 2.0),
        (write(&dir, "t.glb", &glb(&json_glb, &bin)), MeshFormat::Gltf, 2.0),
    ];
    for (path, format, dx) in cases {
        let loaded = load_mesh(&path, &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // tobj numbers OBJ vertices in first-use order: compare geometry, not numbering.
        assert_eq!(canonical(&loaded.mesh), canonical(&expected(dx)), "{}", path.display());
        if format != MeshFormat::Obj {
            assert_eq!(loaded.mesh, expected(dx), "{}", path.display());
        }
        assert_eq!(loaded.report.format, format);
        assert!(loaded.report.topology.is_closed_manifold());
        assert_eq!(loaded.report.topology.components, 1);
    }
}

#[test]
fn ply_quads_are_triangulated_and_binary_matches_ascii() {
    let tmp = common::TempDir::new("ply-quads");
    let dir = tmp.0.clone();
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [9.0, 9.0, 9.0]];
    let f = vec![vec![0, 1, 2, 3]];
    let a = load_mesh(write(&dir, "q.ply", &ply_ascii(&p, &f)), &LoadOptions::default()).unwrap();
    let b = load_mesh(write(&dir, "qb.ply", &ply_binary(&p, &f)), &LoadOptions::default()).unwrap();
    assert_eq!(a.mesh, b.mesh);
    assert_eq!(a.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!((a.report.polygon_faces, a.report.cleanup.unreferenced_vertices), (1, 1));
    assert_eq!(a.report.topology.boundary_edges, 4);
}

/// Loads `name` with `bytes` and returns the error message, checking it names the file.
fn error_of(dir: &Path, name: &str, bytes: &[u8]) -> (Error, String) {
    let path = write(dir, name, bytes);
    let err = match load_mesh(&path, &LoadOptions::default()) {
        Ok(m) => panic!("{name} loaded: {:?}", m.report),
        Err(e) => e,
    };
    let msg = err.to_string();
    assert!(msg.contains(&path.display().to_string()), "{msg}");
    (err, msg)
}

#[test]
fn bad_input_gives_clear_errors() {
    let tmp = common::TempDir::new("bad");
    let dir = tmp.0.clone();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let (e, m) =
        error_of(&dir, "nan.obj", format!("v nan 0 0\n{tri}f 2 3 4\nf 1 2 3\n").as_bytes());
    assert!(matches!(e, Error::Invalid { .. }) && m.contains("non-finite"), "{m}");
    let (_, m) = error_of(&dir, "inf.obj", format!("{tri}v 1 inf 0\nf 1 2 4\n").as_bytes());
    assert!(m.contains("[1.0, inf, 0.0]") && m.contains("non-finite"), "{m}");
    let (_, m) = error_of(&dir, "range.obj", format!("{tri}f 1 2 7\n").as_bytes());
    assert!(m.contains("out of bounds"), "{m}");
    let (_, m) = error_of(&dir, "empty.obj", b"# nothing here\n");
    assert!(m.contains("empty"), "{m}");
    let (_, m) = error_of(&dir, "points.obj", format!("{tri}p 1\n").as_bytes());
    assert!(m.contains("empty"), "{m}");
    let (_, m) = error_of(&dir, "degenerate.obj", format!("{tri}f 1 1 2\n").as_bytes());
    assert!(m.contains("empty"), "{m}");
    let (_, m) = error_of(&dir, "binary.obj", &[0xff, 0xfe, 0x00, 0x9c, 0x10]);
    assert!(m.contains("malformed OBJ"), "{m}");

    let p3 = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let (_, m) = error_of(&dir, "range.ply", &ply_ascii(&p3, &[vec![0, 1, 3]]));
    assert!(m.contains("face 0 refers to vertex 3"), "{m}");
    let (_, m) = error_of(&dir, "negative.ply", &ply_binary(&p3, &[vec![0, -1, 2]]));
    assert!(m.contains("vertex -1"), "{m}");
    let (_, m) =
        error_of(&dir, "nan.ply", &ply_binary(&[[f32::NAN, 0.0, 0.0]; 3], &[vec![0, 1, 2]]));
    assert!(m.contains("non-finite"), "{m}");
    let full = ply_binary(&p3, &[vec![0, 1, 2]]);
    let (e, _) = error_of(&dir, "truncated.ply", &full[..full.len() - 5]);
    assert!(matches!(e, Error::Parse { format: MeshFormat::Ply, .. }));
    let (_, m) = error_of(&dir, "empty.ply", &ply_ascii(&[], &[]));
    assert!(m.contains("empty"), "{m}");

    let (bin, json) = gltf_parts(None);
    let (e, _) = error_of(&dir, "short.glb", &glb(&json, &bin[..40]));
    assert!(matches!(e, Error::Parse { format: MeshFormat::Gltf, .. }));
    let (_, m) = error_of(&dir, "nobuffer.gltf", gltf_parts(Some("missing.bin")).1.as_bytes());
    assert!(m.contains("missing.bin"), "{m}");
    let mut bad_index = bin.clone();
    bad_index[48..50].copy_from_slice(&9u16.to_le_bytes());
    let (_, m) = error_of(&dir, "range.glb", &glb(&json, &bad_index));
    assert!(m.contains("refers to vertex 9"), "{m}");
    let (e, _) = error_of(&dir, "garbage.gltf", b"{ not json");
    assert!(matches!(e, Error::Parse { .. }));

    let (e, m) = error_of(&dir, "mesh.stl", b"solid");
    assert!(matches!(e, Error::UnsupportedFormat { .. }) && m.contains("stl"), "{m}");
    let missing = dir.join("does-not-exist.obj");
    let e = load_mesh(&missing, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("does-not-exist.obj"));
}

/// No single allocation of a loader may exceed 1 GiB: a header claiming 2^40 elements must be an
/// error, not an out-of-memory kill.
#[global_allocator]
static ALLOC: test_support::corrupt::CappedAlloc = test_support::corrupt::CappedAlloc(1 << 30);

/// Corrupted copies of every format (the fixtures above, and Spot from the shared data where it
/// is) give an error or a mesh, never a panic or an unbounded allocation.
#[test]
fn corrupted_meshes_give_errors_not_panics() {
    let tmp = common::TempDir::new("fuzz-mesh");
    let dir = tmp.0.clone();
    let (bin, json_ext) = gltf_parts(Some("tetra.bin"));
    write(&dir, "tetra.bin", &bin);
    let data_uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    let (_, json_data) = gltf_parts(Some(&data_uri));
    let (_, json_glb) = gltf_parts(None);
    let mut obj = vec![
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4/1/1\nf 1 4 3\nf -1 -2 -3\n".to_vec(),
    ];
    if let Some(data) = common::data_dir() {
        obj.push(std::fs::read(data.join("meshes/spot.obj")).unwrap());
    }
    let targets: [(&str, Vec<Vec<u8>>); 4] = [
        ("obj", obj),
        ("ply", vec![ply_ascii(&TETRA_P, &tetra_faces()), ply_binary(&TETRA_P, &tetra_faces())]),
        ("gltf", vec![json_ext.into_bytes(), json_data.into_bytes()]),
        ("glb", vec![glb(&json_glb, &bin)]),
    ];
    for (ext, seeds) in targets {
        let path = dir.join(format!("fuzz.{ext}"));
        let cases = if ext == "obj" { 2000 } else { 5000 };
        test_support::corrupt::fuzz_loader(&format!("mesh-{ext}"), &seeds, cases, |b| {
            std::fs::write(&path, b).unwrap();
            let _ = load_mesh(&path, &LoadOptions::default());
        });
    }
}

/// Found by the test above: a glTF whose `accessors` key is misspelt made the gltf crate's
/// validation index an empty array; and buffer URIs cannot leave the asset's folder.
#[test]
fn dangling_gltf_references_and_escaping_uris_are_errors() {
    let tmp = common::TempDir::new("gltf-refs");
    let dir = tmp.0.clone();
    let (bin, json) = gltf_parts(Some("tetra.bin"));
    write(&dir, "tetra.bin", &bin);
    let (_, m) =
        error_of(&dir, "dangling.gltf", json.replace("\"accessors\"", "\"acc0ssors\"").as_bytes());
    assert!(m.contains("malformed glTF"), "{m}");
    let sub = dir.join("sub");
    std::fs::create_dir_all(&sub).unwrap();
    for uri in ["../tetra.bin", "/etc/hostname", "file:///etc/hostname", "sub/../../tetra.bin"] {
        let (_, m) = error_of(&sub, "escape.gltf", gltf_parts(Some(uri)).1.as_bytes());
        assert!(m.contains("outside the asset's folder"), "{uri}: {m}");
    }
    // A relative path below the folder is read.
    write(&sub, "tetra.bin", &bin);
    let ok = write(&dir, "below.gltf", gltf_parts(Some("./sub/tetra.bin")).1.as_bytes());
    assert!(load_mesh(&ok, &LoadOptions::default()).is_ok());
}
