//! ISO 10303-21 (STEP) output of a [`Brep`]: the analytic entities of AP214
//! (`AUTOMOTIVE_DESIGN`), one `MANIFOLD_SOLID_BREP` per shell when the shells are closed and a
//! `SHELL_BASED_SURFACE_MODEL` of `OPEN_SHELL`s otherwise (a shell: a group of faces joined by
//! edges; several for a cloud that fell apart into pieces).
//!
//! Written by hand: the Rust STEP crates looked at do not serve (truck-stepio writes only
//! shapes built with truck's own modeller, ruststep is marked experimental), and the part of
//! the format a B-rep needs is a few dozen entity kinds of plain text. The file is checked by
//! an independent kernel in the tests (OpenCASCADE, `scripts/check_step.py`).

use std::fmt::Write as _;

use super::{Brep, Curve};
use crate::geometry::vec3::{dot, normalize, scale, sub};
use crate::geometry::{Point3, SurfaceParams};

/// The length unit declared in the file (the coordinates are written as they are).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Millimetres (the default of mechanical CAD).
    #[default]
    Millimetre,
    /// Metres.
    Metre,
    /// Inches.
    Inch,
}

impl std::str::FromStr for LengthUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mm" => Ok(LengthUnit::Millimetre),
            "m" => Ok(LengthUnit::Metre),
            "in" | "inch" => Ok(LengthUnit::Inch),
            other => Err(format!("unknown length unit '{other}' (mm, m or in)")),
        }
    }
}

/// A STEP real: the shortest round-trip digits, always with a decimal point, exponent as `E`.
fn real(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x }; // no "-0."
    let s = format!("{x:?}");
    let (mantissa, exponent) = match s.split_once('e') {
        Some((m, e)) => (m.to_string(), Some(e.to_string())),
        None => (s, None),
    };
    let mut out = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').to_string()
    } else {
        format!("{mantissa}.")
    };
    if let Some(e) = exponent {
        out.push('E');
        out.push_str(&e);
    }
    out
}

fn reals(v: &[f64]) -> String {
    v.iter().map(|&x| real(x)).collect::<Vec<_>>().join(",")
}

fn refs(ids: &[usize]) -> String {
    ids.iter()
        .map(|i| format!("#{i}"))
        .collect::<Vec<_>>()
        .join(",")
}

fn boolean(b: bool) -> &'static str {
    if b {
        ".T."
    } else {
        ".F."
    }
}

/// Any unit vector perpendicular to the unit `z`.
pub(crate) fn perpendicular(z: Point3) -> Point3 {
    let a = if z[0].abs() <= z[1].abs() && z[0].abs() <= z[2].abs() {
        [1.0, 0.0, 0.0]
    } else if z[1].abs() <= z[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    normalize(sub(a, scale(z, dot(a, z)))).unwrap_or([1.0, 0.0, 0.0])
}

/// The entity list of a STEP file under construction.
struct Entities {
    lines: Vec<String>,
}

impl Entities {
    fn add(&mut self, body: String) -> usize {
        self.lines.push(body);
        self.lines.len()
    }
    fn point(&mut self, p: Point3) -> usize {
        self.add(format!("CARTESIAN_POINT('',({}))", reals(&p)))
    }
    fn direction(&mut self, d: Point3) -> usize {
        self.add(format!("DIRECTION('',({}))", reals(&d)))
    }
    fn placement(&mut self, origin: Point3, z: Point3, x: Point3) -> usize {
        let o = self.point(origin);
        let z = self.direction(z);
        let x = self.direction(x);
        self.add(format!("AXIS2_PLACEMENT_3D('',#{o},#{z},#{x})"))
    }

    /// The surface, its parametrisation's seam (and a sphere's poles) placed away from the
    /// face whose mean normal is `direction`: a sphere's pole at the middle of the face (never
    /// on its border), the seam of a surface of revolution along `seam` when given (where the
    /// face's boundary leaves the widest gap), else on the side opposite the face.
    fn surface(&mut self, s: &SurfaceParams, direction: Point3, seam: Option<Point3>) -> usize {
        let away = |axis: Point3| {
            seam.and_then(|x| normalize(sub(x, scale(axis, dot(x, axis)))))
                .or_else(|| normalize(sub(scale(axis, dot(direction, axis)), direction)))
                .unwrap_or_else(|| perpendicular(axis))
        };
        match *s {
            SurfaceParams::Plane { normal, offset } => {
                let a = self.placement(scale(normal, offset), normal, perpendicular(normal));
                self.add(format!("PLANE('',#{a})"))
            }
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                radius,
            } => {
                let a = self.placement(axis_point, axis_dir, away(axis_dir));
                self.add(format!("CYLINDRICAL_SURFACE('',#{a},{})", real(radius)))
            }
            SurfaceParams::Cone {
                apex,
                axis_dir,
                half_angle,
            } => {
                // STEP places the cone by a point of its axis and the radius there; one unit of
                // height from the apex keeps the radius well conditioned.
                let h = 1.0;
                let origin = [
                    apex[0] + h * axis_dir[0],
                    apex[1] + h * axis_dir[1],
                    apex[2] + h * axis_dir[2],
                ];
                let a = self.placement(origin, axis_dir, away(axis_dir));
                self.add(format!(
                    "CONICAL_SURFACE('',#{a},{},{})",
                    real(h * half_angle.tan()),
                    real(half_angle)
                ))
            }
            SurfaceParams::Sphere { center, radius } => {
                let z = normalize(direction).unwrap_or([0.0, 0.0, 1.0]);
                let a = self.placement(center, z, perpendicular(z));
                self.add(format!("SPHERICAL_SURFACE('',#{a},{})", real(radius)))
            }
            SurfaceParams::Torus {
                center,
                axis_dir,
                major_radius,
                minor_radius,
            } => {
                let a = self.placement(center, axis_dir, away(axis_dir));
                self.add(format!(
                    "TOROIDAL_SURFACE('',#{a},{},{})",
                    real(major_radius),
                    real(minor_radius)
                ))
            }
        }
    }

    fn curve(&mut self, c: &Curve) -> usize {
        match c {
            Curve::Line { origin, dir } => {
                let p = self.point(*origin);
                let d = self.direction(*dir);
                let v = self.add(format!("VECTOR('',#{d},1.)"));
                self.add(format!("LINE('',#{p},#{v})"))
            }
            Curve::Circle {
                center,
                axis,
                ref_dir,
                radius,
            } => {
                let a = self.placement(*center, *axis, *ref_dir);
                self.add(format!("CIRCLE('',#{a},{})", real(*radius)))
            }
            Curve::Ellipse {
                center,
                axis,
                ref_dir,
                semi_major,
                semi_minor,
            } => {
                let a = self.placement(*center, *axis, *ref_dir);
                self.add(format!(
                    "ELLIPSE('',#{a},{},{})",
                    real(*semi_major),
                    real(*semi_minor)
                ))
            }
            Curve::BSpline {
                degree,
                control_points,
                knots,
                multiplicities,
            } => {
                let ids: Vec<usize> = control_points.iter().map(|&p| self.point(p)).collect();
                let mults = multiplicities
                    .iter()
                    .map(|m| m.to_string())
                    .collect::<Vec<_>>()
                    .join(",");
                self.add(format!(
                    "B_SPLINE_CURVE_WITH_KNOTS('',{degree},({}),.UNSPECIFIED.,.F.,.F.,({mults}),({}),.UNSPECIFIED.)",
                    refs(&ids),
                    reals(knots)
                ))
            }
        }
    }
}

/// The B-rep as the text of a STEP file. `name` names the product; `uncertainty` is the
/// distance under which the kernel may treat two points as one (the reconstruction's
/// tolerance).
pub fn to_step(brep: &Brep, name: &str, unit: LengthUnit, uncertainty: f64) -> String {
    let mut e = Entities { lines: Vec::new() };
    let name = name.replace(['\'', '\\'], "_");
    let app =
        e.add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')".into());
    e.add(format!(
        "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"
    ));
    let pctx = e.add(format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let product = e.add(format!("PRODUCT('{name}','{name}','',(#{pctx}))"));
    let formation = e.add(format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"));
    let dctx = e.add(format!(
        "PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"
    ));
    let def = e.add(format!(
        "PRODUCT_DEFINITION('design','',#{formation},#{dctx})"
    ));
    let shape = e.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{def})"));
    let length = match unit {
        LengthUnit::Millimetre => {
            e.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))".into())
        }
        LengthUnit::Metre => e.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT($,.METRE.))".into()),
        LengthUnit::Inch => {
            let mm = e.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))".into());
            let measure = e.add(format!(
                "LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#{mm})"
            ));
            let dims = e.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)".into());
            e.add(format!(
                "(CONVERSION_BASED_UNIT('INCH',#{measure})LENGTH_UNIT()NAMED_UNIT(#{dims}))"
            ))
        }
    };
    let angle = e.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))".into());
    let solid_angle = e.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())".into());
    let unc = e.add(format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{length},'distance_accuracy_value','maximum gap between the reconstructed faces')",
        real(uncertainty)
    ));
    let ctx = e.add(format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc}))GLOBAL_UNIT_ASSIGNED_CONTEXT((#{length},#{angle},#{solid_angle}))REPRESENTATION_CONTEXT('3D','3D context with units and uncertainty'))"
    ));

    let vertices: Vec<usize> = brep
        .vertices
        .iter()
        .map(|&p| {
            let pt = e.point(p);
            e.add(format!("VERTEX_POINT('',#{pt})"))
        })
        .collect();
    let edges: Vec<usize> = brep
        .edges
        .iter()
        .map(|edge| {
            let c = e.curve(&edge.curve);
            e.add(format!(
                "EDGE_CURVE('',#{},#{},#{c},{})",
                vertices[edge.start],
                vertices[edge.end],
                boolean(edge.curve_sense)
            ))
        })
        .collect();
    let mut faces = Vec::with_capacity(brep.faces.len());
    for face in &brep.faces {
        let surface = e.surface(&face.surface, face.direction, face.seam);
        let mut bounds = Vec::with_capacity(face.loops.len());
        for (li, lp) in face.loops.iter().enumerate() {
            let oriented: Vec<usize> = lp
                .iter()
                .map(|&(edge, forward)| {
                    e.add(format!(
                        "ORIENTED_EDGE('',*,*,#{},{})",
                        edges[edge],
                        boolean(forward)
                    ))
                })
                .collect();
            let l = e.add(format!("EDGE_LOOP('',({}))", refs(&oriented)));
            let kind = if face.outer == Some(li) {
                "FACE_OUTER_BOUND"
            } else {
                "FACE_BOUND"
            };
            bounds.push(e.add(format!("{kind}('',#{l},.T.)")));
        }
        faces.push(e.add(format!(
            "ADVANCED_FACE('',({}),#{surface},{})",
            refs(&bounds),
            boolean(face.same_sense)
        )));
    }
    let origin = e.placement([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    // One shell per group of faces joined by edges (a cloud that fell apart into pieces).
    let shells: Vec<Vec<usize>> = super::assembly::shells(brep.faces.len(), &brep.edges)
        .into_iter()
        .map(|group| group.into_iter().map(|f| faces[f]).collect())
        .collect();
    let representation = if brep.closed {
        let solids: Vec<usize> = shells
            .iter()
            .map(|group| {
                let shell = e.add(format!("CLOSED_SHELL('',({}))", refs(group)));
                e.add(format!("MANIFOLD_SOLID_BREP('{name}',#{shell})"))
            })
            .collect();
        e.add(format!(
            "ADVANCED_BREP_SHAPE_REPRESENTATION('{name}',({},#{origin}),#{ctx})",
            refs(&solids)
        ))
    } else {
        let open: Vec<usize> = shells
            .iter()
            .map(|group| e.add(format!("OPEN_SHELL('',({}))", refs(group))))
            .collect();
        let model = e.add(format!(
            "SHELL_BASED_SURFACE_MODEL('{name}',({}))",
            refs(&open)
        ));
        e.add(format!(
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('{name}',(#{model},#{origin}),#{ctx})"
        ))
    };
    e.add(format!(
        "SHAPE_DEFINITION_REPRESENTATION(#{shape},#{representation})"
    ));

    let mut out = String::new();
    out.push_str("ISO-10303-21;\nHEADER;\n");
    out.push_str("FILE_DESCRIPTION(('B-rep reconstructed from a scan by crease'),'2;1');\n");
    let _ = writeln!(
        out,
        "FILE_NAME('{name}','',(''),(''),'crease {}','crease','');",
        env!("CARGO_PKG_VERSION")
    );
    out.push_str("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n");
    for (i, line) in e.lines.iter().enumerate() {
        let _ = writeln!(out, "#{}={};", i + 1, line);
    }
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_follow_the_step_syntax() {
        assert_eq!(real(1.0), "1.");
        assert_eq!(real(-0.0), "0.");
        assert_eq!(real(0.25), "0.25");
        assert_eq!(real(1e-7), "1.E-7");
        assert_eq!(real(-2.5e20), "-2.5E20");
        assert_eq!(real(123456.0), "123456.");
        // Round trip of the digits.
        let x = 0.1 + 0.2;
        assert_eq!(real(x).parse::<f64>().ok(), Some(x));
    }

    #[test]
    fn perpendicular_is_unit_and_orthogonal() {
        for z in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.6, 0.8, 0.0],
            [0.0, -1.0, 0.0],
        ] {
            let x = perpendicular(z);
            assert!(dot(x, z).abs() < 1e-15);
            assert!((dot(x, x) - 1.0).abs() < 1e-15);
        }
    }
}
