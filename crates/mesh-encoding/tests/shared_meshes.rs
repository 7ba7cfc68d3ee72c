//! Loads all 14 meshes of the shared data folder and checks counts, the known defects of each
//! (polygon faces in beast, unreferenced vertices and holes in the bunny, boundaries in suzanne
//! and the teapot, a closed spot), normals and normalisation.

mod common;

use mesh_encoding::{LoadOptions, NormalWeighting, load_mesh};

/// (file, vertices in the file, faces in the file), from the data folder's README.
const MESHES: &[(&str, usize, usize)] = &[
    ("suzanne.obj", 507, 500),
    ("woody.obj", 694, 1267),
    ("cow.obj", 2903, 5804),
    ("spot.obj", 2930, 5856),
    ("alligator.obj", 3208, 5981),
    ("teapot.obj", 3644, 6320),
    ("homer.obj", 6002, 12000),
    ("fandisk.obj", 6475, 12946),
    ("cheburashka.obj", 6669, 13334),
    ("rocker-arm.obj", 10044, 20088),
    ("beast.obj", 32311, 32364),
    ("stanford-bunny.obj", 35947, 69451),
    ("nefertiti.obj", 49971, 99938),
    ("ogre.obj", 62194, 124008),
];

#[test]
fn all_fourteen_meshes_load_clean_and_normalise() {
    let Some(data) = common::data_dir() else { return };
    let options = LoadOptions { normalize_unit_sphere: true, ..Default::default() };
    for &(name, vertices, faces) in MESHES {
        let loaded = load_mesh(data.join("meshes").join(name), &options)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = &loaded.report;
        let m = &loaded.mesh;
        println!("{name}: {:?} {:?} polygons {}", r.cleanup, r.topology, r.polygon_faces);
        assert_eq!((r.file_vertices, r.file_faces), (vertices, faces), "{name}");
        assert_eq!(m.vertex_count() + r.cleanup.unreferenced_vertices, vertices, "{name}");
        assert!(m.triangle_count() >= faces - r.cleanup.degenerate_triangles, "{name}");
        m.validate().unwrap();
        assert_eq!(r.topology.triangles, m.triangle_count());

        // Normalised into the unit sphere, the farthest vertex on it.
        let radius = m.positions.iter().map(|p| p.length()).fold(0.0f32, f32::max);
        assert!((radius - 1.0).abs() < 1e-5, "{name}: radius {radius}");

        for w in [NormalWeighting::Angle, NormalWeighting::Area] {
            let n = m.vertex_normals(w);
            assert_eq!(n.len(), m.vertex_count());
            assert!(n.iter().all(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-5), "{name}");
        }
    }
}

fn load(name: &str) -> Option<mesh_encoding::LoadedMesh> {
    let data = common::data_dir()?;
    Some(load_mesh(data.join("meshes").join(name), &LoadOptions::default()).unwrap())
}

#[test]
fn beast_polygons_are_triangulated() {
    let Some(beast) = load("beast.obj") else { return };
    assert_eq!(beast.report.polygon_faces, 32240);
    // Every quad becomes two triangles (fewer only if some were degenerate or duplicated).
    assert!(beast.mesh.triangle_count() > 32364 + 32240 - 100);
}

#[test]
fn bunny_has_unreferenced_vertices_and_holes() {
    let Some(bunny) = load("stanford-bunny.obj") else { return };
    let r = &bunny.report;
    assert!(r.cleanup.unreferenced_vertices > 0, "{r:?}");
    assert!(r.topology.boundary_edges > 0, "{r:?}");
}

#[test]
fn suzanne_and_teapot_have_boundaries_spot_is_closed() {
    let Some(suzanne) = load("suzanne.obj") else { return };
    assert!(suzanne.report.topology.boundary_edges > 0);
    assert_eq!(suzanne.report.polygon_faces, 468);
    let teapot = load("teapot.obj").unwrap();
    assert!(teapot.report.topology.boundary_edges > 0);
    let spot = load("spot.obj").unwrap();
    assert!(spot.report.topology.is_closed_manifold(), "{:?}", spot.report.topology);
    assert_eq!(spot.report.topology.components, 1);
}

/// On a closed mesh the vertex normals point outwards: the surface integral of n . (p - c) is
/// three times the enclosed volume, positive for outward normals.
#[test]
fn spot_normals_point_outwards() {
    let Some(spot) = load("spot.obj") else { return };
    let m = &spot.mesh;
    let (lo, hi) = m.bounding_box();
    let c = 0.5 * (lo + hi);
    let n = m.vertex_normals(NormalWeighting::Angle);
    let outward = m.positions.iter().zip(&n).filter(|(p, n)| n.dot(**p - c) > 0.0).count();
    assert!(outward as f64 > 0.8 * m.vertex_count() as f64, "{outward} of {}", m.vertex_count());
}
