//! What `crease info` reports about a loaded file: kind, counts, bounding box, spacing,
//! attributes with their ranges, and the problems found (dropped points, duplicates, mesh defects).

use rayon::prelude::*;
use serde::Serialize;

use super::{Geometry, ReadReport};
use crate::geometry::{
    clean_mesh, Aabb, Attribute, Attributes, CleanupParams, MeshTopology, Point3, TriMesh,
};
use crate::spatial::average_spacing;

/// A summary of one attribute column.
#[derive(Debug, Clone, Serialize)]
pub struct AttributeSummary {
    /// Property name.
    pub name: String,
    /// PLY type name (`uchar`, `int`, `float`, ...).
    pub kind: &'static str,
    /// Smallest finite value.
    pub min: Option<f64>,
    /// Largest finite value.
    pub max: Option<f64>,
    /// For integer attributes with at most 20 distinct values: (value, count), ascending.
    pub histogram: Option<Vec<(i64, usize)>>,
}

/// Problems found in the data, each a count (0 = none).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Problems {
    /// Points dropped on reading because a coordinate was NaN or infinite.
    pub dropped_nonfinite: usize,
    /// Points the format marked as missing (organised PCD), dropped on reading.
    pub dropped_missing: usize,
    /// Faces dropped with those points.
    pub dropped_faces: usize,
    /// Points at exactly the same position as an earlier point.
    pub duplicate_points: usize,
}

/// Topology and defects of a triangle mesh, as read (before any clean-up).
#[derive(Debug, Clone, Default, Serialize)]
pub struct MeshSummary {
    /// Every edge has two faces, consistently oriented, and every vertex is a disk.
    pub closed_manifold: bool,
    /// Unique undirected edges.
    pub edges: usize,
    /// Connected components (by faces).
    pub components: usize,
    /// V - E + F.
    pub euler_characteristic: i64,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Closed loops of boundary edges.
    pub boundary_loops: usize,
    /// Edges with more than two faces.
    pub non_manifold_edges: usize,
    /// Vertices whose faces do not form one fan.
    pub non_manifold_vertices: usize,
    /// Edges whose two faces traverse them in the same direction.
    pub inconsistent_edges: usize,
    /// Vertices the clean-up would merge (coincident within its tolerance).
    pub coincident_vertices: usize,
    /// Faces with a repeated corner or (near) zero area.
    pub degenerate_faces: usize,
    /// Faces with the same corners as an earlier face.
    pub duplicate_faces: usize,
    /// Vertices no face uses.
    pub isolated_vertices: usize,
    /// Edges with a dihedral angle above 30 degrees (a first look at the sharp edges).
    pub edges_above_30_degrees: usize,
}

/// Computes the mesh summary of `mesh`, or a message saying why it could not be computed.
pub fn summarize_mesh(mesh: &TriMesh) -> crate::Result<MeshSummary> {
    let topo = MeshTopology::new(mesh)?;
    let (_, clean) = clean_mesh(mesh, &CleanupParams::default())?;
    let limit = 30f64.to_radians();
    Ok(MeshSummary {
        closed_manifold: topo.is_closed_manifold(),
        edges: topo.num_edges(),
        components: topo.num_components(),
        euler_characteristic: topo.euler_characteristic(),
        boundary_edges: topo.boundary_edges().len(),
        boundary_loops: topo.num_boundary_loops(),
        non_manifold_edges: topo.non_manifold_edges().len(),
        non_manifold_vertices: topo.non_manifold_vertices().len(),
        inconsistent_edges: topo.inconsistent_edges().len(),
        coincident_vertices: clean.vertices_merged,
        degenerate_faces: clean.degenerate_faces + clean.zero_area_faces,
        duplicate_faces: clean.duplicate_faces,
        isolated_vertices: clean.isolated_vertices,
        edges_above_30_degrees: topo
            .dihedral_angles()
            .iter()
            .filter(|a| **a > limit)
            .count(),
    })
}

/// Everything `crease info` prints.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// "point cloud", "triangle mesh" or "polylines".
    pub kind: &'static str,
    /// Format encoding detail from the reader.
    pub encoding: String,
    /// Number of points (mesh vertices).
    pub points: usize,
    /// Number of triangles.
    pub faces: usize,
    /// Number of line segments.
    pub edges: usize,
    /// Number of polylines.
    pub polylines: usize,
    /// Bounding box.
    pub bbox: Option<Aabb>,
    /// Bounding-box diagonal.
    pub diagonal: Option<f64>,
    /// Mean nearest-neighbour distance.
    pub spacing: Option<f64>,
    /// Point clouds: the noise, the standard deviation of the points across the surface
    /// ([`crate::estimate::noise::noise_sigma`]).
    pub noise: Option<f64>,
    /// Whether normals are stored.
    pub normals: bool,
    /// Whether colours are stored.
    pub colors: bool,
    /// Per-point attributes.
    pub attributes: Vec<AttributeSummary>,
    /// Per-face attributes.
    pub face_attributes: Vec<AttributeSummary>,
    /// Per-edge attributes.
    pub edge_attributes: Vec<AttributeSummary>,
    /// Problems found.
    pub problems: Problems,
    /// Mesh topology and defects, for meshes.
    pub mesh: Option<MeshSummary>,
    /// Reader notes.
    pub notes: Vec<String>,
}

/// Summarises a loaded geometry (the mesh-specific part is added by the caller from the
/// mesh topology and clean-up reports).
pub fn summarize(geom: &Geometry, report: &ReadReport) -> Summary {
    let pts = &geom.points.positions;
    let bbox = Aabb::from_points(pts);
    let kind = if !geom.faces.is_empty() {
        "triangle mesh"
    } else if pts.is_empty() || geom.edges.is_empty() && geom.polylines.is_empty() {
        "point cloud"
    } else {
        "polylines"
    };
    Summary {
        kind,
        encoding: report.encoding.clone(),
        points: pts.len(),
        faces: geom.faces.len(),
        edges: geom.edges.len(),
        polylines: geom.polylines.len(),
        bbox,
        diagonal: bbox.map(|b| b.diagonal()),
        spacing: average_spacing(pts),
        noise: (kind == "point cloud")
            .then(|| crate::estimate::noise::noise_sigma(pts))
            .flatten(),
        normals: geom.points.normals.is_some(),
        colors: geom.points.colors.is_some(),
        attributes: summarize_attributes(&geom.points.attributes),
        face_attributes: summarize_attributes(&geom.face_attributes),
        edge_attributes: summarize_attributes(&geom.edge_attributes),
        problems: Problems {
            dropped_nonfinite: report.dropped_nonfinite,
            dropped_missing: report.dropped_missing,
            dropped_faces: report.dropped_faces,
            duplicate_points: count_duplicate_points(pts),
        },
        mesh: None,
        notes: report.notes.clone(),
    }
}

fn summarize_attributes(attrs: &Attributes) -> Vec<AttributeSummary> {
    attrs.iter().map(summarize_attribute).collect()
}

fn summarize_attribute(a: &Attribute) -> AttributeSummary {
    let finite = a.values.iter().copied().filter(|v| v.is_finite());
    let (min, max) = finite.fold((None, None), |(lo, hi): (Option<f64>, Option<f64>), v| {
        (
            Some(lo.map_or(v, |l| l.min(v))),
            Some(hi.map_or(v, |h| h.max(v))),
        )
    });
    let histogram = a.kind.is_integer().then(|| {
        let mut m = std::collections::BTreeMap::<i64, usize>::new();
        for &v in &a.values {
            *m.entry(v as i64).or_default() += 1;
            if m.len() > 20 {
                return None;
            }
        }
        Some(m.into_iter().collect::<Vec<_>>())
    });
    AttributeSummary {
        name: a.name.clone(),
        kind: a.kind.ply_name(),
        min,
        max,
        histogram: histogram.flatten(),
    }
}

/// Number of points whose position equals (bit for bit, with -0 = +0) an earlier point's.
pub fn count_duplicate_points(points: &[Point3]) -> usize {
    let key = |p: &Point3| p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
    let mut keys: Vec<[u64; 3]> = points.par_iter().map(key).collect();
    keys.par_sort_unstable();
    keys.windows(2).filter(|w| w[0] == w[1]).count()
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "kind        {} ({})", self.kind, self.encoding)?;
        write!(f, "points      {}", self.points)?;
        if self.faces > 0 {
            write!(f, "   faces {}", self.faces)?;
        }
        if self.edges > 0 {
            write!(f, "   edges {}", self.edges)?;
        }
        if self.polylines > 0 {
            write!(f, "   polylines {}", self.polylines)?;
        }
        writeln!(f)?;
        if let Some(b) = &self.bbox {
            let e = b.extent();
            writeln!(
                f,
                "bbox        [{:.6}, {:.6}, {:.6}] .. [{:.6}, {:.6}, {:.6}]",
                b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]
            )?;
            writeln!(
                f,
                "extent      {:.6} x {:.6} x {:.6}   diagonal {:.6}",
                e[0],
                e[1],
                e[2],
                b.diagonal()
            )?;
        }
        match self.spacing {
            Some(s) => writeln!(f, "spacing     {s:.6} (mean nearest-neighbour distance)")?,
            None => writeln!(f, "spacing     undefined (fewer than two distinct points)")?,
        }
        if let Some(n) = self.noise {
            match self.spacing.filter(|&s| s > 0.0) {
                Some(s) => writeln!(
                    f,
                    "noise       {n:.6} ({:.2} × the spacing above; σ of the points across the surface)",
                    n / s
                )?,
                None => writeln!(f, "noise       {n:.6} (σ of the points across the surface)")?,
            }
        }
        writeln!(
            f,
            "normals     {}   colors {}",
            if self.normals { "yes" } else { "no" },
            if self.colors { "yes" } else { "no" }
        )?;
        for (title, list) in [
            ("point attributes", &self.attributes),
            ("face attributes", &self.face_attributes),
            ("edge attributes", &self.edge_attributes),
        ] {
            if list.is_empty() {
                continue;
            }
            writeln!(f, "{title}:")?;
            for a in list {
                write!(f, "  {:<20} {:<6}", a.name, a.kind)?;
                if let (Some(lo), Some(hi)) = (a.min, a.max) {
                    write!(f, " range [{lo}, {hi}]")?;
                }
                if let Some(h) = &a.histogram {
                    let parts: Vec<String> = h.iter().map(|(v, c)| format!("{v}: {c}")).collect();
                    write!(f, "  counts {{{}}}", parts.join(", "))?;
                }
                writeln!(f)?;
            }
        }
        let p = &self.problems;
        let mut problems = Vec::new();
        if p.dropped_nonfinite > 0 {
            problems.push(format!(
                "{} points with NaN/infinite coordinates dropped",
                p.dropped_nonfinite
            ));
        }
        if p.dropped_missing > 0 {
            problems.push(format!(
                "{} missing points (no return) dropped",
                p.dropped_missing
            ));
        }
        if p.dropped_faces > 0 {
            problems.push(format!(
                "{} faces dropped with those points",
                p.dropped_faces
            ));
        }
        if p.duplicate_points > 0 {
            problems.push(format!("{} duplicate points", p.duplicate_points));
        }
        if problems.is_empty() {
            writeln!(f, "problems    none found")?;
        } else {
            writeln!(f, "problems    {}", problems.join("; "))?;
        }
        if let Some(m) = &self.mesh {
            writeln!(
                f,
                "mesh        {} edges, {} component(s), Euler characteristic {}, {}",
                m.edges,
                m.components,
                m.euler_characteristic,
                if m.closed_manifold {
                    "closed manifold"
                } else {
                    "not a closed manifold"
                }
            )?;
            let defects = [
                (m.boundary_edges, "boundary edges"),
                (m.boundary_loops, "boundary loops"),
                (m.non_manifold_edges, "non-manifold edges"),
                (m.non_manifold_vertices, "non-manifold vertices"),
                (m.inconsistent_edges, "inconsistently oriented edges"),
                (m.coincident_vertices, "coincident vertices"),
                (m.degenerate_faces, "degenerate faces"),
                (m.duplicate_faces, "duplicate faces"),
                (m.isolated_vertices, "isolated vertices"),
            ];
            let found: Vec<String> = defects
                .iter()
                .filter(|(n, _)| *n > 0)
                .map(|(n, what)| format!("{n} {what}"))
                .collect();
            if !found.is_empty() {
                writeln!(f, "mesh issues {}", found.join("; "))?;
            }
            writeln!(
                f,
                "dihedral    {} edges above 30 degrees",
                m.edges_above_30_degrees
            )?;
        }
        for n in &self.notes {
            writeln!(f, "note        {n}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicates_counted_once_each_and_signed_zero_equal() {
        let p = vec![
            [0.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [1.0, 2.0, 3.0],
            [1.0, 2.0, 3.0],
            [4.0, 0.0, 0.0],
        ];
        assert_eq!(count_duplicate_points(&p), 3);
    }
}
