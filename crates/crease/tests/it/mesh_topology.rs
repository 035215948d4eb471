//! Mesh topology and clean-up on meshes built in code, with exact expected values.

use std::f64::consts::FRAC_PI_2;

use crease::geometry::topology::NO_EDGE;
use crease::geometry::{
    clean_mesh, face_normal, Attribute, CleanupParams, MeshTopology, TriMesh, VertexKind,
};
use proptest::prelude::*;

/// Unit cube, vertex `x + 2y + 4z`, 12 triangles counter-clockwise seen from outside.
fn cube() -> TriMesh {
    let mut p = Vec::new();
    for i in 0..8 {
        p.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
    }
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut f = Vec::new();
    for q in quads {
        f.push([q[0], q[1], q[2]]);
        f.push([q[0], q[2], q[3]]);
    }
    TriMesh::new(p, f).unwrap()
}

/// Closed L-shaped prism: polygon (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) extruded over z in [0, 1].
/// Bottom vertices 0..6, top 6..12. The vertical edge (3, 9) is concave.
fn l_prism() -> TriMesh {
    let poly = [
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for q in poly {
            p.push([q[0], q[1], z]);
        }
    }
    let mut f = Vec::new();
    // Fans from the reflex vertex 3: top CCW from above, bottom reversed.
    for [a, b] in [[4, 5], [5, 0], [0, 1], [1, 2]] {
        f.push([3 + 6, a + 6, b + 6]);
        f.push([3, b, a]);
    }
    for i in 0..6u32 {
        let j = (i + 1) % 6;
        f.push([i, j, j + 6]);
        f.push([i, j + 6, i + 6]);
    }
    TriMesh::new(p, f).unwrap()
}

/// Flat `nx × ny` grid of unit squares, each split along the same diagonal.
fn grid(nx: u32, ny: u32) -> TriMesh {
    let mut p = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            p.push([i as f64, j as f64, 0.0]);
        }
    }
    let id = |i: u32, j: u32| j * (nx + 1) + i;
    let mut f = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    TriMesh::new(p, f).unwrap()
}

/// Checks every structural invariant that holds for any mesh.
fn check_invariants(m: &TriMesh, t: &MeshTopology) {
    let edges = t.edges();
    assert!(edges.iter().all(|e| e[0] < e[1]));
    assert!(
        edges.windows(2).all(|w| w[0] < w[1]),
        "edges sorted and unique"
    );
    let mut sides = 0;
    for (f, face) in m.faces.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (face[i], face[(i + 1) % 3]);
            let e = t.face_edges()[f][i];
            if a == b {
                assert_eq!(e, NO_EDGE);
            } else {
                sides += 1;
                assert_eq!(edges[e as usize], [a.min(b), a.max(b)]);
                assert_eq!(t.edge_index(a as usize, b as usize), Some(e as usize));
            }
        }
    }
    assert_eq!(t.edge_face_csr().indices.len(), sides);
    for (e, &[a, b]) in edges.iter().enumerate() {
        let fs = t.edge_faces(e);
        assert!(!fs.is_empty());
        assert!(fs.windows(2).all(|w| w[0] <= w[1]));
        for (&f, &s) in fs.iter().zip(t.edge_face_sides(e)) {
            let face = m.faces[f as usize];
            let (p, q) = (face[s as usize], face[(s as usize + 1) % 3]);
            assert_eq!([p.min(q), p.max(q)], [a, b]);
        }
        assert!(t.vertex_edges(a as usize).contains(&(e as u32)));
        assert!(t.vertex_edges(b as usize).contains(&(e as u32)));
    }
    let mut nref = 0;
    for v in 0..m.num_vertices() {
        let vf = t.vertex_faces(v);
        let mut direct: Vec<u32> = (0..m.num_faces() as u32)
            .filter(|&f| m.faces[f as usize].contains(&(v as u32)))
            .collect();
        let mut sorted = vf.to_vec();
        sorted.sort_unstable();
        direct.sort_unstable();
        assert_eq!(sorted, direct);
        nref += usize::from(!vf.is_empty());
        let nb: Vec<u32> = t.neighbors(v).collect();
        assert!(nb.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(nb.len(), t.vertex_edges(v).len());
        match t.one_ring(v) {
            None => assert_eq!(t.vertex_kind(v), VertexKind::NonManifold),
            Some(r) => {
                let k = r.faces.len();
                assert_eq!(
                    r.neighbors.len(),
                    if r.closed || k == 0 { k } else { k + 1 }
                );
                for (j, &f) in r.faces.iter().enumerate() {
                    let face = m.faces[f as usize];
                    let a = r.neighbors[j];
                    let b = r.neighbors[(j + 1) % r.neighbors.len()];
                    assert!(face.contains(&(v as u32)) && face.contains(&a) && face.contains(&b));
                }
                let mut ring = r.neighbors.to_vec();
                ring.sort_unstable();
                assert_eq!(
                    ring, nb,
                    "a manifold vertex's ring holds all its neighbours"
                );
            }
        }
    }
    assert_eq!(
        t.euler_characteristic(),
        nref as i64 - edges.len() as i64 + m.num_faces() as i64
    );
    assert_eq!(t.face_components().len(), m.num_faces());
}

#[test]
fn cube_topology() {
    let m = cube();
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    // outward normals
    for f in 0..12 {
        let n = face_normal(&m, f);
        let c: [f64; 3] = m.triangle(f).iter().fold([0.0; 3], |s, p| {
            [s[0] + p[0] / 3.0, s[1] + p[1] / 3.0, s[2] + p[2] / 3.0]
        });
        let out = (c[0] - 0.5) * n[0] + (c[1] - 0.5) * n[1] + (c[2] - 0.5) * n[2];
        assert!(out > 0.0);
    }
    assert_eq!(t.num_edges(), 18);
    assert!(t.is_closed_manifold());
    assert!(t.is_oriented());
    assert_eq!(t.euler_characteristic(), 2);
    assert_eq!(t.num_components(), 1);
    assert_eq!(t.num_boundary_loops(), 0);
    assert!(t.boundary_edges().is_empty());
    assert!(t.inconsistent_edges().is_empty());
    let mut right = 0;
    let mut flat = 0;
    for e in 0..18 {
        let [a, b] = t.edges()[e];
        let d = a ^ b; // differing coordinate bits
        let diagonal = d.count_ones() == 2;
        let (u, s) = (t.dihedral_angles()[e], t.signed_dihedral_angles()[e]);
        if diagonal {
            assert_eq!(u, 0.0);
            assert_eq!(s, 0.0);
            flat += 1;
        } else {
            assert!((u - FRAC_PI_2).abs() < 1e-15, "{u}");
            assert_eq!(s, u);
            right += 1;
        }
    }
    assert_eq!((right, flat), (12, 6));
    for v in 0..8 {
        let r = t.one_ring(v).unwrap();
        assert!(r.closed);
        assert_eq!(t.vertex_kind(v), VertexKind::Interior);
        assert_eq!(r.neighbors.len(), t.vertex_faces(v).len());
        assert_eq!(r.neighbors.len(), t.neighbors(v).len());
    }
    // Vertex 0 lies on 3 diagonals (0-3, 0-5, 0-6) and 3 axis edges: 6 neighbours, 6 faces.
    assert_eq!(t.neighbors(0).collect::<Vec<_>>(), vec![1, 2, 3, 4, 5, 6]);
    // Vertices 0 and 7 end three diagonals (6 faces); the others end one (4 faces).
    for v in 0..8 {
        let expected = if v == 0 || v == 7 { 6 } else { 4 };
        assert_eq!(t.vertex_faces(v).len(), expected);
    }
    // Fan order follows face orientation: CCW around the vertex seen from outside.
    let r = t.one_ring(0).unwrap();
    for (j, &f) in r.faces.iter().enumerate() {
        let face = m.faces[f as usize];
        let a = r.neighbors[j];
        let b = r.neighbors[(j + 1) % r.neighbors.len()];
        let i = face.iter().position(|&x| x == 0).unwrap();
        assert_eq!([face[(i + 1) % 3], face[(i + 2) % 3]], [a, b]);
    }
    assert_eq!(r.faces[0], t.vertex_faces(0).iter().copied().min().unwrap());
}

#[test]
fn cube_with_a_flipped_face() {
    let mut m = cube();
    m.faces[5].swap(1, 2);
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    assert_eq!(t.inconsistent_edges().len(), 3);
    assert!(!t.is_oriented());
    assert!(t.is_closed_manifold());
    for &e in t.inconsistent_edges() {
        assert!(t.edge_faces(e as usize).contains(&5));
        assert!(t.signed_dihedral_angles()[e as usize].is_nan());
        // the angle between the stored normals: flipped face gives π - bend
        let u = t.dihedral_angles()[e as usize];
        assert!(
            u == std::f64::consts::PI || (u - FRAC_PI_2).abs() < 1e-15,
            "{u}"
        );
    }
    // vertices stay manifold (closed fans), rings still hold all neighbours
    assert!(t.non_manifold_vertices().is_empty());
}

#[test]
fn inside_out_cube_is_concave_everywhere() {
    let mut m = cube();
    for f in &mut m.faces {
        f.swap(1, 2);
    }
    let t = MeshTopology::new(&m).unwrap();
    assert!(t.is_oriented());
    let s = t.signed_dihedral_angles();
    assert_eq!(
        s.iter().filter(|&&a| (a + FRAC_PI_2).abs() < 1e-15).count(),
        12
    );
    assert_eq!(s.iter().filter(|&&a| a == 0.0).count(), 6);
}

#[test]
fn l_prism_concave_edge() {
    let m = l_prism();
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    assert_eq!(t.num_edges(), 30);
    assert!(t.is_closed_manifold());
    assert!(t.is_oriented());
    assert_eq!(t.euler_characteristic(), 2);
    let s = t.signed_dihedral_angles();
    let concave = t.edge_index(3, 9).unwrap();
    assert!((s[concave] + FRAC_PI_2).abs() < 1e-15, "{}", s[concave]);
    for v in [0usize, 1, 2, 4, 5] {
        let e = t.edge_index(v, v + 6).unwrap();
        assert!((s[e] - FRAC_PI_2).abs() < 1e-15);
    }
    let negative = s.iter().filter(|&&a| a < 0.0).count();
    assert_eq!(negative, 1);
    // perimeter edges of top and bottom: convex right angles
    for i in 0..6 {
        let j = (i + 1) % 6;
        for off in [0, 6] {
            let e = t.edge_index(i + off, j + off).unwrap();
            assert!((s[e] - FRAC_PI_2).abs() < 1e-15);
        }
    }
}

#[test]
fn open_grid() {
    let (nx, ny) = (4, 3);
    let m = grid(nx, ny);
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    assert_eq!(t.boundary_edges().len(), (2 * (nx + ny)) as usize);
    assert_eq!(t.num_boundary_loops(), 1);
    assert_eq!(t.euler_characteristic(), 1);
    assert!(!t.is_closed_manifold());
    assert!(t.is_manifold());
    assert!(t.dihedral_angles().iter().all(|&a| a.is_nan() || a == 0.0));
    let mut boundary = 0;
    for v in 0..m.num_vertices() {
        let (i, j) = (v as u32 % (nx + 1), v as u32 / (nx + 1));
        let on_boundary = i == 0 || j == 0 || i == nx || j == ny;
        let r = t.one_ring(v).unwrap();
        assert_eq!(r.closed, !on_boundary);
        if on_boundary {
            boundary += 1;
            assert_eq!(t.vertex_kind(v), VertexKind::Boundary);
            assert_eq!(r.neighbors.len(), r.faces.len() + 1);
            // the open fan starts and ends on boundary edges
            let first = t.edge_index(v, r.neighbors[0] as usize).unwrap();
            let last = t
                .edge_index(v, *r.neighbors.last().unwrap() as usize)
                .unwrap();
            assert!(t.is_boundary_edge(first) && t.is_boundary_edge(last));
        } else {
            assert_eq!(r.neighbors.len(), 6);
        }
    }
    assert_eq!(boundary, 2 * (nx + ny));
    // corner (0,0) is on both triangles of its square; corner (nx,0) on one.
    assert_eq!(t.one_ring(0).unwrap().faces.len(), 2);
    assert_eq!(t.one_ring(nx as usize).unwrap().faces.len(), 1);
    assert_eq!(
        t.one_ring(nx as usize).unwrap().neighbors,
        &[nx + 1 + nx, nx - 1]
    );
}

#[test]
fn non_manifold_edge() {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, 1.0],
    ];
    let m = TriMesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    let e = t.edge_index(0, 1).unwrap();
    assert_eq!(t.non_manifold_edges(), &[e as u32]);
    assert_eq!(t.edge_faces(e), &[0, 1, 2]);
    assert!(t.dihedral_angles()[e].is_nan());
    assert_eq!(t.non_manifold_vertices(), &[0, 1]);
    assert!(t.one_ring(0).is_none());
    assert!(!t.is_manifold());
    assert_eq!(t.boundary_edges().len(), 6);
    assert_eq!(t.num_components(), 1);
}

#[test]
fn two_tetrahedra_sharing_a_vertex() {
    let mut p = vec![[0.0, 0.0, 0.0]];
    for s in [1.0, -1.0] {
        p.push([s, 0.0, 0.0]);
        p.push([0.0, s, 0.0]);
        p.push([0.0, 0.0, s]);
    }
    // tetra on vertices 0,a,b,c with outward orientation depends on s; topology only here.
    let mut f = Vec::new();
    for base in [1u32, 4] {
        let (a, b, c) = (base, base + 1, base + 2);
        f.extend([[0, b, a], [0, a, c], [0, c, b], [a, b, c]]);
    }
    let m = TriMesh::new(p, f).unwrap();
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    assert_eq!(t.num_edges(), 12);
    assert!(t.non_manifold_edges().is_empty());
    assert!(t.boundary_edges().is_empty());
    assert_eq!(t.non_manifold_vertices(), &[0]);
    assert_eq!(t.vertex_kind(0), VertexKind::NonManifold);
    assert!(!t.is_closed_manifold());
    assert_eq!(t.num_components(), 2);
    assert_eq!(t.face_components(), &[0, 0, 0, 0, 1, 1, 1, 1]);
    assert_eq!(t.euler_characteristic(), 7 - 12 + 8);
    assert!(t.is_oriented());
    for v in 1..7 {
        assert!(t.one_ring(v).unwrap().closed);
    }
}

#[test]
fn two_holes_touching_at_a_vertex_are_two_loops() {
    // Two triangles sharing only vertex 0: two boundary loops, vertex 0 non-manifold.
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -1.0, 0.0],
    ];
    let m = TriMesh::new(p, vec![[0, 1, 2], [0, 3, 4]]).unwrap();
    let t = MeshTopology::new(&m).unwrap();
    check_invariants(&m, &t);
    assert_eq!(t.num_boundary_loops(), 2);
    assert_eq!(t.non_manifold_vertices(), &[0]);
    assert_eq!(t.num_components(), 2);
}

/// The cube as an STL-like soup: every triangle with its own three vertices.
fn cube_soup(jitter: f64) -> TriMesh {
    let c = cube();
    let mut p = Vec::new();
    let mut f = Vec::new();
    for (k, face) in c.faces.iter().enumerate() {
        let base = p.len() as u32;
        for (i, &v) in face.iter().enumerate() {
            let q = c.positions()[v as usize];
            let s = if (k + i) % 2 == 0 { jitter } else { -jitter };
            p.push([q[0] + s, q[1] - s, q[2] + 0.5 * s]);
        }
        f.push([base, base + 1, base + 2]);
    }
    TriMesh::new(p, f).unwrap()
}

#[test]
fn soup_cleanup_gives_the_cube() {
    for jitter in [0.0, 1e-12] {
        let soup = cube_soup(jitter);
        let (m, r) = clean_mesh(&soup, &CleanupParams::default()).unwrap();
        assert_eq!(m.num_vertices(), 8);
        assert_eq!(m.num_faces(), 12);
        assert_eq!(r.vertices_merged, 28);
        assert_eq!(
            (r.degenerate_faces, r.duplicate_faces, r.isolated_vertices),
            (0, 0, 0)
        );
        let t = MeshTopology::new(&m).unwrap();
        assert!(t.is_closed_manifold());
        assert!(t.is_oriented());
        assert_eq!(t.num_edges(), 18);
        assert_eq!(t.euler_characteristic(), 2);
        // representatives are the first occurrences, in input order
        assert_eq!(r.vertex_origin, vec![0, 1, 2, 5, 6, 7, 8, 11]);
        assert_eq!(r.vertex_map[0], 0);
        assert_eq!(r.face_map, (0..12).collect::<Vec<u32>>());
    }
    // Without merging, the soup is 12 separate triangles.
    let p = CleanupParams {
        merge_vertices: false,
        ..Default::default()
    };
    let (m, r) = clean_mesh(&cube_soup(0.0), &p).unwrap();
    assert_eq!((m.num_vertices(), r.vertices_merged), (36, 0));
    let t = MeshTopology::new(&m).unwrap();
    assert_eq!((t.num_components(), t.num_boundary_loops()), (12, 12));
}

#[test]
fn cleanup_counts_and_maps() {
    let mut soup = cube_soup(0.0);
    let n0 = soup.num_vertices() as u32;
    // a repeated-vertex face after merging: soup vertices 0 and 3 are both the cube's vertex 0
    soup.faces.insert(2, [0, 3, 1]);
    // a zero-area face: two cube corners and the midpoint of their edge (a new vertex)
    soup.vertices.positions.push([0.5, 0.0, 0.0]);
    soup.faces.push([0, n0, 5]); // soup vertex 5 is the cube's vertex 1 = (1, 0, 0)
                                 // a duplicate of face 0 with the other orientation, and an exact copy of face 7
    let f0 = soup.faces[0];
    soup.faces.push([f0[0], f0[2], f0[1]]);
    let f7 = soup.faces[7];
    soup.faces.push(f7);
    // an unreferenced vertex
    soup.vertices.positions.push([5.0, 5.0, 5.0]);
    let nf = soup.num_faces();
    soup.set_face_attribute(Attribute::int("label", 0..nf as i64))
        .unwrap();
    let nv = soup.num_vertices();
    soup.vertices
        .set_attribute(Attribute::int("id", 0..nv as i64))
        .unwrap();

    let (m, r) = clean_mesh(&soup, &CleanupParams::default()).unwrap();
    assert_eq!((m.num_vertices(), m.num_faces()), (8, 12));
    assert_eq!(r.input_faces, 16);
    assert_eq!(r.degenerate_faces, 2);
    assert_eq!(r.zero_area_faces, 1);
    assert_eq!(r.duplicate_faces, 2);
    assert_eq!(r.isolated_vertices, 2);
    assert_eq!(r.vertices_merged, 28);
    assert!(MeshTopology::new(&m).unwrap().is_closed_manifold());
    // face attributes follow faces, vertex attributes follow kept vertices
    let labels = m.face_attributes.get("label").unwrap().as_i64();
    assert_eq!(
        labels,
        r.face_map.iter().map(|&f| f as i64).collect::<Vec<_>>()
    );
    let ids = m.vertices.attribute("id").unwrap().as_i64();
    assert_eq!(
        ids,
        r.vertex_origin
            .iter()
            .map(|&v| v as i64)
            .collect::<Vec<_>>()
    );
    // per-output-face values back to input order
    let back = r.face_values_to_input(&labels, -1).unwrap();
    let mut expected: Vec<i64> = (0..nf as i64).collect();
    expected[2] = -1; // repeated vertex
    expected[13] = -1; // zero area
    expected[14] = 0; // duplicate of face 0
    expected[15] = 7; // copy of input face 7
    assert_eq!(back, expected);
    let vback = r.vertex_values_to_input(&ids, -1).unwrap();
    assert_eq!(vback[3], 0);
    assert_eq!(vback[nv - 1], -1);
    assert_eq!(vback[nv - 2], -1);
    assert_eq!(r.face_values_from_input(&expected).unwrap(), labels);
    assert!(r.face_values_to_input(&labels[..3], -1).is_err());
    // summary
    let s = r.to_string();
    assert!(
        s.contains("38 -> 8 vertices") && s.contains("16 -> 12 faces"),
        "{s}"
    );
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["duplicate_faces"], 2);
    assert!(json.get("vertex_map").is_none());
}

#[test]
fn cleanup_keeps_per_vertex_data_of_representative() {
    let mut m = TriMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
        ],
        vec![[0, 3, 2]],
    )
    .unwrap();
    m.vertices
        .set_colors(vec![[1, 1, 1], [2, 2, 2], [3, 3, 3], [4, 4, 4]])
        .unwrap();
    let (c, r) = clean_mesh(&m, &CleanupParams::default()).unwrap();
    assert_eq!(c.faces, vec![[0, 1, 2]]);
    assert_eq!(
        c.vertices.colors.unwrap(),
        vec![[1, 1, 1], [2, 2, 2], [3, 3, 3]]
    );
    assert_eq!(r.vertex_map, vec![0, 1, 2, 1]);
}

#[test]
fn large_grid_counts() {
    let n = 500u32;
    let m = grid(n, n);
    let t = MeshTopology::new(&m).unwrap();
    let f = 2 * n * n;
    let b = 4 * n;
    assert_eq!(t.num_faces(), f as usize);
    assert_eq!(t.boundary_edges().len(), b as usize);
    assert_eq!(t.num_edges(), (3 * f / 2 + b / 2) as usize);
    assert_eq!(t.euler_characteristic(), 1);
    assert_eq!(t.num_boundary_loops(), 1);
    assert_eq!(t.num_components(), 1);
    assert!(t.is_manifold() && t.is_oriented());
    let interior = (n - 1) * (n - 1);
    let closed = (0..m.num_vertices())
        .filter(|&v| t.vertex_kind(v) == VertexKind::Interior)
        .count();
    assert_eq!(closed, interior as usize);
}

/// CPU seconds used by this process so far (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let Some(rest) = stat.rsplit(')').next() else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11).and_then(|x| x.parse().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|x| x.parse().ok()).unwrap_or(0.0);
    ticks / 100.0
}

/// Times topology and clean-up on ~1M triangles (a grid with shuffled vertex ids).
/// `cargo test --release -p crease --test it mesh_topology:: -- --ignored --nocapture`
#[test]
#[ignore]
fn timing_one_million_triangles() {
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let n = 708u32;
    let g = grid(n, n);
    let mut perm: Vec<u32> = (0..g.num_vertices() as u32).collect();
    perm.shuffle(&mut rand_pcg::Pcg64::seed_from_u64(7));
    let mut pos = vec![[0.0; 3]; perm.len()];
    for (i, &p) in perm.iter().enumerate() {
        pos[p as usize] = g.positions()[i];
    }
    let faces: Vec<[u32; 3]> = g
        .faces
        .iter()
        .map(|f| f.map(|v| perm[v as usize]))
        .collect();
    let m = TriMesh::new(pos, faces).unwrap();
    for _ in 0..3 {
        let (t0, c0) = (std::time::Instant::now(), cpu_seconds());
        let t = MeshTopology::new(&m).unwrap();
        eprintln!(
            "topology: {} faces, {} edges in {:.3} s wall, {:.2} s cpu",
            t.num_faces(),
            t.num_edges(),
            t0.elapsed().as_secs_f64(),
            cpu_seconds() - c0
        );
    }
    // the same mesh as an STL soup
    let mut p = Vec::with_capacity(3 * m.num_faces());
    let mut f = Vec::with_capacity(m.num_faces());
    for face in &m.faces {
        let base = p.len() as u32;
        for &v in face {
            p.push(m.positions()[v as usize]);
        }
        f.push([base, base + 1, base + 2]);
    }
    let soup = TriMesh::new(p, f).unwrap();
    for _ in 0..2 {
        let (t0, c0) = (std::time::Instant::now(), cpu_seconds());
        let (c, r) = clean_mesh(&soup, &CleanupParams::default()).unwrap();
        eprintln!(
            "{r} in {:.3} s wall, {:.2} s cpu",
            t0.elapsed().as_secs_f64(),
            cpu_seconds() - c0
        );
        assert_eq!(c.num_vertices(), m.num_vertices());
    }
}

fn random_mesh() -> impl Strategy<Value = TriMesh> {
    (1usize..9).prop_flat_map(|nv| {
        let faces = prop::collection::vec(
            (0..nv as u32, 0..nv as u32, 0..nv as u32).prop_map(|(a, b, c)| [a, b, c]),
            0..24,
        );
        let pos = prop::collection::vec(
            (0i32..3, 0i32..3, 0i32..3).prop_map(|(x, y, z)| [x as f64, y as f64, z as f64]),
            nv,
        );
        (pos, faces).prop_map(|(p, f)| TriMesh::new(p, f).unwrap())
    })
}

proptest! {
    #[test]
    fn random_meshes_keep_invariants(m in random_mesh()) {
        let t = MeshTopology::new(&m).unwrap();
        check_invariants(&m, &t);
        let distinct: Vec<bool> = m.faces.iter().map(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2]).collect();
        if distinct.iter().all(|&d| d) {
            prop_assert_eq!(t.edge_face_csr().indices.len(), 3 * m.num_faces());
        }
        let (c, r) = clean_mesh(&m, &CleanupParams::default()).unwrap();
        let tc = MeshTopology::new(&c).unwrap();
        check_invariants(&c, &tc);
        prop_assert!(tc.degenerate_faces().is_empty());
        prop_assert_eq!(tc.num_referenced_vertices(), c.num_vertices());
        let mut keys: Vec<[u32; 3]> = c.faces.iter().map(|f| { let mut k = *f; k.sort_unstable(); k }).collect();
        keys.sort_unstable();
        keys.dedup();
        prop_assert_eq!(keys.len(), c.num_faces());
        prop_assert_eq!(r.face_map.len(), c.num_faces());
        for (o, &f) in r.face_map.iter().enumerate() {
            let mapped = m.faces[f as usize].map(|v| r.vertex_map[v as usize]);
            prop_assert_eq!(mapped, c.faces[o]);
            prop_assert_eq!(r.face_target[f as usize], o as u32);
        }
        for (i, &o) in r.vertex_map.iter().enumerate() {
            if o != u32::MAX {
                prop_assert_eq!(c.positions()[o as usize], m.positions()[i]);
            }
        }
    }
}
