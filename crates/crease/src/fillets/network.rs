//! The whole curve network: the sharp and the smooth lines merged into one vertex set.

use super::Fillets;
use crate::geometry::{names, Point3};

/// The whole curve network: sharp and smooth lines (and the cloud's open border) in one vertex
/// set, each polyline tagged.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CurveNetwork {
    /// Vertex positions (the sharp network's first).
    pub vertices: Vec<Point3>,
    /// Polylines; a closed loop repeats its first vertex.
    pub polylines: Vec<Vec<u32>>,
    /// Per polyline: true for a smooth (fillet) line, false for a sharp one.
    pub smooth: Vec<bool>,
    /// Per polyline: true for the cloud's open border (the sharp network's
    /// [`crate::lines::LineNetwork::boundary_lines`]), which is no feature line.
    pub boundary: Vec<bool>,
    /// Smooth-line ends joined to the sharp line they meet.
    pub joined_ends: usize,
    /// Smooth-line ends left open.
    pub open_ends: usize,
}

impl CurveNetwork {
    /// Per polyline, its group: [`names::SHARP`], [`names::SMOOTH`] or [`names::BOUNDARY`]
    /// (the OBJ `g` the CLI writes).
    pub fn groups(&self) -> Vec<&'static str> {
        self.smooth
            .iter()
            .zip(&self.boundary)
            .map(|(&smooth, &border)| match (smooth, border) {
                (true, _) => names::SMOOTH,
                (false, true) => names::BOUNDARY,
                (false, false) => names::SHARP,
            })
            .collect()
    }

    /// Polylines in the group `name` ([`CurveNetwork::groups`]).
    pub fn count(&self, name: &str) -> usize {
        self.groups().iter().filter(|&&g| g == name).count()
    }
}

/// Merges the sharp and the smooth lines of `f` into one network. A smooth line that ends on
/// its region's boundary (next to a sharp edge) is extended to the nearest sharp-line vertex
/// when that lies within `3 ×` the median edge length of the smooth lines (the band between a
/// region's border points and the sharp line is one or two spacings wide), so that the
/// network a CAD user receives is connected as the paper's figures show it.
pub fn curve_network(f: &Fillets) -> CurveNetwork {
    let mut net = CurveNetwork::default();
    if let Some(sharp) = &f.sharp {
        net.vertices.extend_from_slice(&sharp.vertices);
        net.polylines.extend(sharp.polylines.iter().cloned());
        net.smooth
            .extend(std::iter::repeat_n(false, sharp.polylines.len()));
        net.boundary.extend_from_slice(&sharp.boundary_lines);
    }
    let base = net.vertices.len() as u32;
    let l = &f.lines;
    net.vertices.extend_from_slice(&l.vertices);
    let mut lengths: Vec<f64> = l
        .edges
        .iter()
        .map(|e| crate::geometry::vec3::dist(l.vertices[e[0] as usize], l.vertices[e[1] as usize]))
        .collect();
    lengths.sort_by(f64::total_cmp);
    let reach = 3.0 * lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
    let sharp_index = f
        .sharp
        .as_ref()
        .and_then(|s| crate::spatial::KdIndex::new(&s.vertices));
    let mut degree = vec![0u32; l.vertices.len()];
    for e in &l.edges {
        degree[e[0] as usize] += 1;
        degree[e[1] as usize] += 1;
    }
    for line in &l.polylines {
        let mut out: Vec<u32> = line.iter().map(|&v| v + base).collect();
        let closed = line.len() > 2 && line.first() == line.last();
        if !closed {
            for at_end in [false, true] {
                let v = if at_end {
                    line[line.len() - 1]
                } else {
                    line[0]
                } as usize;
                if degree[v] != 1 {
                    continue;
                }
                let near = sharp_index
                    .as_ref()
                    .filter(|_| l.on_boundary[v])
                    .and_then(|idx| idx.nearest(&l.vertices[v], 1).first().copied())
                    .filter(|&(_, d2)| d2.sqrt() <= reach);
                match near {
                    Some((s, _)) => {
                        net.joined_ends += 1;
                        if at_end {
                            out.push(s);
                        } else {
                            out.insert(0, s);
                        }
                    }
                    None => net.open_ends += 1,
                }
            }
        }
        net.polylines.push(out);
        net.smooth.push(true);
        net.boundary.push(false);
    }
    net
}
