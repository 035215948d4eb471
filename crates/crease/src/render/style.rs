//! Turns a [`ColorBy`] choice into colours for the points and the mesh, and into the matching
//! legend content.
//!
//! * `Uniform`: points in one colour, lit by the headlight when they carry normals; meshes in
//!   a light blue-grey, always lit.
//! * `Rgb`: the stored colours (points; mesh vertex colours interpolated).
//! * `Normal`: `(n + 1) / 2` as RGB (mesh: vertex normals, else face normals).
//! * `Attribute(name)`: looked up on the points, then on the mesh vertices, then on the mesh
//!   faces; one [`Scheme`] is chosen from all the values found so that points and mesh agree.
//!   Point colours are exact palette colours (no lighting), so they match the legend.

use rayon::prelude::*;

use super::colormap::{Scheme, UNASSIGNED};
use super::{ColorBy, Scene};
use crate::geometry::Point3;
use crate::{Error, Result};

/// Default point colour for `ColorBy::Uniform`.
pub(crate) const UNIFORM_POINT: [u8; 3] = [120, 150, 192];
/// Default mesh colour for `ColorBy::Uniform` (before lighting).
pub(crate) const UNIFORM_MESH: [u8; 3] = [176, 190, 208];

/// How points get their colour.
pub(crate) enum PointStyle<'a> {
    /// One exact colour per point.
    Fixed(Vec<[u8; 3]>),
    /// A base colour lit per view by the headlight through the point normals.
    Lit([u8; 3], &'a [Point3]),
    /// One colour for all.
    Flat([u8; 3]),
}

/// How mesh pixels get their colour (before lighting).
pub(crate) enum MeshStyle {
    /// One colour.
    Uniform([u8; 3]),
    /// Per-vertex colours interpolated across faces.
    VertexInterp(Vec<[u8; 3]>),
    /// Per-vertex labels: each pixel takes the colour of the face corner it is nearest to.
    VertexNearest(Vec<[u8; 3]>),
    /// Per-vertex values in [0, 1] (NaN for missing) interpolated, then mapped through viridis.
    VertexScalar(Vec<f32>),
    /// One colour per face.
    Face(Vec<[u8; 3]>),
}

/// What the legend explains about the colours.
pub(crate) enum LegendBody {
    /// Nothing (uniform colour).
    None,
    /// The stored RGB colours.
    Rgb,
    /// Normal directions as RGB.
    Normal,
    /// An attribute and how it was mapped.
    Attribute {
        /// The attribute's name.
        name: String,
        /// The mapping.
        scheme: Scheme,
    },
}

/// Colours for everything in a scene.
pub(crate) struct Style<'a> {
    /// Point colouring (when the scene has points).
    pub points: Option<PointStyle<'a>>,
    /// Mesh colouring (when the scene has a mesh).
    pub mesh: Option<MeshStyle>,
    /// Legend content.
    pub legend: LegendBody,
}

fn normal_rgb(n: Point3) -> [u8; 3] {
    if !(n[0].is_finite() && n[1].is_finite() && n[2].is_finite()) {
        return UNASSIGNED;
    }
    let f = |v: f64| ((v.clamp(-1.0, 1.0) + 1.0) * 127.5).round() as u8;
    [f(n[0]), f(n[1]), f(n[2])]
}

fn names(a: &crate::geometry::Attributes) -> String {
    if a.is_empty() {
        "(none)".to_string()
    } else {
        a.iter()
            .map(|x| x.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Resolves `color_by` for `scene`. Fails when the requested data is absent everywhere: no
/// colours for `Rgb`, no normals on the points for `Normal`, or no attribute of that name (the
/// message lists the attributes that exist).
pub(crate) fn resolve<'a>(scene: &Scene<'a>, color_by: &ColorBy) -> Result<Style<'a>> {
    let points = scene.points.filter(|p| !p.is_empty());
    let mesh = scene.mesh.filter(|m| !m.faces.is_empty());
    match color_by {
        ColorBy::Uniform => Ok(Style {
            points: points.map(|p| match &p.normals {
                Some(n) if n.len() == p.len() => PointStyle::Lit(UNIFORM_POINT, n.as_slice()),
                _ => PointStyle::Flat(UNIFORM_POINT),
            }),
            mesh: mesh.map(|_| MeshStyle::Uniform(UNIFORM_MESH)),
            legend: LegendBody::None,
        }),
        ColorBy::Rgb => {
            let pc = points.and_then(|p| p.colors.as_ref().filter(|c| c.len() == p.len()));
            let mc = mesh.and_then(|m| {
                m.vertices
                    .colors
                    .as_ref()
                    .filter(|c| c.len() == m.num_vertices())
            });
            if pc.is_none() && mc.is_none() {
                return Err(Error::InvalidInput(
                    "colour by RGB: neither the points nor the mesh vertices have colours".into(),
                ));
            }
            Ok(Style {
                points: points.map(|_| match pc {
                    Some(c) => PointStyle::Fixed(c.clone()),
                    None => PointStyle::Flat(UNASSIGNED),
                }),
                mesh: mesh.map(|_| match mc {
                    Some(c) => MeshStyle::VertexInterp(c.clone()),
                    None => MeshStyle::Uniform(UNIFORM_MESH),
                }),
                legend: LegendBody::Rgb,
            })
        }
        ColorBy::Normal => {
            let pn = points.map(|p| p.normals.as_ref().filter(|n| n.len() == p.len()));
            if let Some(None) = pn {
                return Err(Error::InvalidInput(
                    "colour by normal: the point cloud has no normals (estimate them first)".into(),
                ));
            }
            let point_style = pn
                .flatten()
                .map(|n| PointStyle::Fixed(n.par_iter().map(|&v| normal_rgb(v)).collect()));
            let mesh_style = mesh.map(|m| match &m.vertices.normals {
                Some(n) if n.len() == m.num_vertices() => {
                    MeshStyle::VertexInterp(n.par_iter().map(|&v| normal_rgb(v)).collect())
                }
                _ => MeshStyle::Face(
                    m.faces
                        .par_iter()
                        .map(|f| {
                            let p = m.positions();
                            let g = |i: u32| p.get(i as usize).copied().unwrap_or([f64::NAN; 3]);
                            let (a, b, c) = (g(f[0]), g(f[1]), g(f[2]));
                            use crate::geometry::vec3::{cross, normalize, sub};
                            normalize(cross(sub(b, a), sub(c, a))).map_or(UNASSIGNED, normal_rgb)
                        })
                        .collect(),
                ),
            });
            Ok(Style {
                points: point_style,
                mesh: mesh_style,
                legend: LegendBody::Normal,
            })
        }
        ColorBy::Attribute(name) => {
            let pa = points.and_then(|p| p.attribute(name).filter(|a| a.values.len() == p.len()));
            // A mesh attribute present per face and per vertex is drawn per face: faces are
            // the unit of mesh labels (segments, surface ids), and per-vertex copies of them
            // blur the borders between regions.
            let fa = mesh.and_then(|m| {
                m.face_attributes
                    .get(name)
                    .filter(|a| a.values.len() == m.num_faces())
            });
            let va = if fa.is_none() {
                mesh.and_then(|m| {
                    m.vertices
                        .attribute(name)
                        .filter(|a| a.values.len() == m.num_vertices())
                })
            } else {
                None
            };
            if pa.is_none() && va.is_none() && fa.is_none() {
                let mut msg = format!("no attribute named {name:?} to colour by; available:");
                if let Some(p) = scene.points {
                    msg += &format!(" points: {};", names(&p.attributes));
                }
                if let Some(m) = scene.mesh {
                    msg += &format!(
                        " mesh vertices: {}; mesh faces: {};",
                        names(&m.vertices.attributes),
                        names(&m.face_attributes)
                    );
                }
                if scene.points.is_none() && scene.mesh.is_none() {
                    msg += " none (the scene has no points and no mesh);";
                }
                msg.pop();
                return Err(Error::InvalidInput(msg));
            }
            let carriers: Vec<&crate::geometry::Attribute> =
                [pa, va, fa].into_iter().flatten().collect();
            let integer_kind = carriers.iter().any(|a| a.kind.is_integer());
            let all: Vec<f64> = carriers
                .iter()
                .flat_map(|a| a.values.iter().copied())
                .collect();
            let scheme = Scheme::choose(name, integer_kind, &all);
            let point_style = points.map(|_| match pa {
                Some(a) => {
                    PointStyle::Fixed(a.values.par_iter().map(|&v| scheme.color(v)).collect())
                }
                None => PointStyle::Flat(UNASSIGNED),
            });
            let continuous = matches!(scheme, Scheme::Continuous { .. });
            let mesh_style = mesh.map(|_| {
                if let Some(a) = va {
                    if continuous {
                        MeshStyle::VertexScalar(
                            a.values
                                .par_iter()
                                .map(|&v| scheme.unit(v).map_or(f32::NAN, |t| t as f32))
                                .collect(),
                        )
                    } else {
                        MeshStyle::VertexNearest(
                            a.values.par_iter().map(|&v| scheme.color(v)).collect(),
                        )
                    }
                } else if let Some(a) = fa {
                    MeshStyle::Face(a.values.par_iter().map(|&v| scheme.color(v)).collect())
                } else {
                    MeshStyle::Uniform(UNASSIGNED)
                }
            });
            Ok(Style {
                points: point_style,
                mesh: mesh_style,
                legend: LegendBody::Attribute {
                    name: name.clone(),
                    scheme,
                },
            })
        }
    }
}
