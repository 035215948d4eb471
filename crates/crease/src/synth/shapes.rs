//! The synthetic test shapes and their exact boundary representation (patches + feature
//! curves).
//!
//! Shapes follow the papers' test objects: the cube (Tran et al., sec. 4.1.1; Demarsin 2007,
//! Fig. 7), two intersecting cylinders (Demarsin 2007, Figs. 1–6), the rounded cube with fillets
//! of radius r and spherical corners (Demarsin 2008, Fig. 7), a block with fillet, chamfer and
//! cone frustum, and the analytic primitives of Mizoguchi et al. (plane, cylinder, cone, sphere,
//! torus). Solids are closed; the single primitives are open surfaces whose patch borders are
//! [`CurveKind::Boundary`] curves (open boundaries, not sharp edges); the sphere and the torus
//! have no curve at all.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::surfaces::{frame, Domain, Patch, Region2, Surface, Trim};
use super::truth::{CurveKind, FeatureCurve};
use crate::geometry::vec3::{dot, scale};
use crate::geometry::SurfaceParams;
use crate::geometry::{Aabb, Point3};
use crate::{Error, Result};

/// A synthetic test shape with its dimensions. Every shape is centred near the origin; the
/// defaults (`Shape::from_name`) have a largest extent of about 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Axis-aligned cube of side `size`, centred at the origin (default size 1). 6 planes,
    /// 12 sharp edges of total length 12·size.
    Cube {
        /// Side length.
        size: f64,
    },
    /// Axis-aligned box `size[0] × size[1] × size[2]` centred at the origin, with a cylindrical
    /// through-hole of radius `hole_radius` along z (default 1 × 1 × 0.5, radius 0.2). Genus 1.
    /// Sharp: the 12 box edges and the 2 hole circles.
    BoxWithHole {
        /// Side lengths along x, y, z.
        size: [f64; 3],
        /// Radius of the hole (its axis is the z axis).
        hole_radius: f64,
    },
    /// Union of two capped solid cylinders whose axes cross at right angles at the origin
    /// (Demarsin 2007's test shape): cylinder A of radius `radius_a` along z, z in
    /// [-`half_length_a`, `half_length_a`]; cylinder B of radius `radius_b` < `radius_a` along x,
    /// x in [-`half_length_b`, `half_length_b`] (default 0.5 / 0.75 and 0.3 / 1.0). B pierces A,
    /// giving two closed sharp intersection curves; plus the 4 cap circles.
    TwoCylinders {
        /// Radius of cylinder A (axis z).
        radius_a: f64,
        /// Half length of cylinder A.
        half_length_a: f64,
        /// Radius of cylinder B (axis x), smaller than `radius_a`.
        radius_b: f64,
        /// Half length of cylinder B.
        half_length_b: f64,
    },
    /// Cube of side `size` centred at the origin with every edge filleted with radius `radius`
    /// and spherical corner patches (default 1, 0.1): 6 planes, 12 quarter cylinders, 8 sphere
    /// octants, no sharp edge. Smooth curves: the 24 plane / fillet borders and the 24
    /// fillet / corner quarter circles.
    RoundedCube {
        /// Side length (outer).
        size: f64,
        /// Fillet radius, < size / 2.
        radius: f64,
    },
    /// Box x in [-length/2, length/2], y in [-width/2, width/2], z in [0, height] (default
    /// 1.2 × 0.8 × 0.4) whose top edge at y = +width/2 is filleted (radius `fillet_radius`,
    /// default 0.1) and whose top edge at y = -width/2 is chamfered at 45° (leg `chamfer`,
    /// default 0.1), with a cone frustum (base radius 0.2, top radius 0.1, height 0.25, with a
    /// flat top) standing on the middle of the top face. Sharp: box edges, chamfer borders,
    /// fillet end arcs, cone base and top circles; smooth: the 2 fillet borders.
    FilletChamferCone {
        /// Extent along x.
        length: f64,
        /// Extent along y.
        width: f64,
        /// Extent along z (box only).
        height: f64,
        /// Radius of the fillet on the top edge at y = +width/2.
        fillet_radius: f64,
        /// Leg length of the 45° chamfer on the top edge at y = -width/2.
        chamfer: f64,
        /// Radius of the cone frustum at its base (on the top face).
        cone_base_radius: f64,
        /// Radius of the cone frustum's flat top, in (0, base radius).
        cone_top_radius: f64,
        /// Height of the cone frustum.
        cone_height: f64,
    },
    /// Open square patch of side `size` in the plane z = 0 (normal +z), default 1. Its 4 sides
    /// are boundary curves.
    Plane {
        /// Side length.
        size: f64,
    },
    /// Open tube around the z axis, z in [-height/2, height/2] (default radius 0.5, height 1).
    /// Its 2 rims are boundary curves.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Height.
        height: f64,
    },
    /// Open cone frustum around the z axis from radius `bottom_radius` at z = 0 to
    /// `top_radius` at z = `height` (default 0.5, 0.25, 0.5). Its 2 rims are boundary curves.
    Cone {
        /// Radius at z = 0.
        bottom_radius: f64,
        /// Radius at z = height, smaller than `bottom_radius`.
        top_radius: f64,
        /// Height.
        height: f64,
    },
    /// Sphere centred at the origin (default radius 0.5). No curves.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// Ring torus around the z axis centred at the origin (default major radius 0.5, minor
    /// radius 0.2). No curves.
    Torus {
        /// Distance from the axis to the tube centre.
        major_radius: f64,
        /// Tube radius, smaller than `major_radius`.
        minor_radius: f64,
    },
}

const NAMES: &[&str] = &[
    "cube",
    "box-hole",
    "two-cylinders",
    "rounded-cube",
    "fillet-chamfer-cone",
    "plane",
    "cylinder",
    "cone",
    "sphere",
    "torus",
];

impl Shape {
    /// The names `from_name` accepts.
    pub fn names() -> &'static [&'static str] {
        NAMES
    }

    /// The shape called `name`, with its default dimensions (see each variant).
    pub fn from_name(name: &str) -> Option<Shape> {
        Some(match name {
            "cube" => Shape::default_cube(),
            "box-hole" => Shape::BoxWithHole {
                size: [1.0, 1.0, 0.5],
                hole_radius: 0.2,
            },
            "two-cylinders" => Shape::TwoCylinders {
                radius_a: 0.5,
                half_length_a: 0.75,
                radius_b: 0.3,
                half_length_b: 1.0,
            },
            "rounded-cube" => Shape::RoundedCube {
                size: 1.0,
                radius: 0.1,
            },
            "fillet-chamfer-cone" => Shape::FilletChamferCone {
                length: 1.2,
                width: 0.8,
                height: 0.4,
                fillet_radius: 0.1,
                chamfer: 0.1,
                cone_base_radius: 0.2,
                cone_top_radius: 0.1,
                cone_height: 0.25,
            },
            "plane" => Shape::Plane { size: 1.0 },
            "cylinder" => Shape::Cylinder {
                radius: 0.5,
                height: 1.0,
            },
            "cone" => Shape::Cone {
                bottom_radius: 0.5,
                top_radius: 0.25,
                height: 0.5,
            },
            "sphere" => Shape::Sphere { radius: 0.5 },
            "torus" => Shape::Torus {
                major_radius: 0.5,
                minor_radius: 0.2,
            },
            _ => return None,
        })
    }

    /// The unit cube.
    pub fn default_cube() -> Shape {
        Shape::Cube { size: 1.0 }
    }

    /// The shape's name (as accepted by `from_name`).
    pub fn name(&self) -> &'static str {
        match self {
            Shape::Cube { .. } => "cube",
            Shape::BoxWithHole { .. } => "box-hole",
            Shape::TwoCylinders { .. } => "two-cylinders",
            Shape::RoundedCube { .. } => "rounded-cube",
            Shape::FilletChamferCone { .. } => "fillet-chamfer-cone",
            Shape::Plane { .. } => "plane",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Cone { .. } => "cone",
            Shape::Sphere { .. } => "sphere",
            Shape::Torus { .. } => "torus",
        }
    }

    /// True if the shape is a closed solid (its surface has no boundary).
    pub fn is_solid(&self) -> bool {
        !matches!(
            self,
            Shape::Plane { .. } | Shape::Cylinder { .. } | Shape::Cone { .. }
        )
    }

    /// The exact model: patches, curves and bounding box.
    pub(crate) fn model(&self) -> Result<Model> {
        let mut b = Builder::default();
        match *self {
            Shape::Cube { size } => {
                positive("cube size", size)?;
                b.set_size(size);
                b.box_faces([size; 3], None);
                b.box_edges([size; 3]);
            }
            Shape::BoxWithHole { size, hole_radius } => {
                for s in size {
                    positive("box-hole size", s)?;
                }
                positive("box-hole hole_radius", hole_radius)?;
                if 2.0 * hole_radius >= size[0].min(size[1]) {
                    return Err(Error::InvalidInput(format!(
                        "box-hole: hole radius {hole_radius} must be smaller than half the box's x and y sizes {size:?}"
                    )));
                }
                b.set_size(size[0].max(size[1]).max(size[2]));
                b.box_faces(size, Some(hole_radius));
                b.box_edges(size);
                let hz = size[2] / 2.0;
                b.patch(
                    Domain::Cylinder {
                        center: [0.0; 3],
                        axis: Z,
                        e1: X,
                        e2: Y,
                        radius: hole_radius,
                        theta0: 0.0,
                        sweep: TAU,
                        h: [-hz, hz],
                        inward: true,
                    },
                    SurfaceParams::Cylinder {
                        axis_point: [0.0; 3],
                        axis_dir: Z,
                        radius: hole_radius,
                    },
                    Trim::None,
                    None,
                );
                for z in [-hz, hz] {
                    b.circle(CurveKind::Sharp, [0.0, 0.0, z], X, Y, hole_radius);
                }
            }
            Shape::TwoCylinders {
                radius_a,
                half_length_a,
                radius_b,
                half_length_b,
            } => two_cylinders(&mut b, radius_a, half_length_a, radius_b, half_length_b)?,
            Shape::RoundedCube { size, radius } => {
                positive("rounded-cube size", size)?;
                positive("rounded-cube radius", radius)?;
                if 2.0 * radius >= size {
                    return Err(Error::InvalidInput(format!(
                        "rounded-cube: radius {radius} must be smaller than half the size {size}"
                    )));
                }
                b.set_size(size);
                rounded_cube(&mut b, size, radius);
            }
            Shape::FilletChamferCone {
                length,
                width,
                height,
                fillet_radius,
                chamfer,
                cone_base_radius,
                cone_top_radius,
                cone_height,
            } => fillet_chamfer_cone(
                &mut b,
                [length, width, height],
                fillet_radius,
                chamfer,
                [cone_base_radius, cone_top_radius, cone_height],
            )?,
            Shape::Plane { size } => {
                positive("plane size", size)?;
                b.set_size(size);
                let h = size / 2.0;
                b.plane_rect([0.0; 3], X, Y, [-h, h], [-h, h], Z, Trim::None, None);
                let c = [[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]];
                for i in 0..4 {
                    b.segment(CurveKind::Boundary, c[i], c[(i + 1) % 4]);
                }
            }
            Shape::Cylinder { radius, height } => {
                positive("cylinder radius", radius)?;
                positive("cylinder height", height)?;
                b.set_size((2.0 * radius).max(height));
                let hz = height / 2.0;
                b.patch(
                    Domain::Cylinder {
                        center: [0.0; 3],
                        axis: Z,
                        e1: X,
                        e2: Y,
                        radius,
                        theta0: 0.0,
                        sweep: TAU,
                        h: [-hz, hz],
                        inward: false,
                    },
                    SurfaceParams::Cylinder {
                        axis_point: [0.0; 3],
                        axis_dir: Z,
                        radius,
                    },
                    Trim::None,
                    None,
                );
                for z in [-hz, hz] {
                    b.circle(CurveKind::Boundary, [0.0, 0.0, z], X, Y, radius);
                }
            }
            Shape::Cone {
                bottom_radius,
                top_radius,
                height,
            } => {
                positive("cone bottom_radius", bottom_radius)?;
                positive("cone top_radius", top_radius)?;
                positive("cone height", height)?;
                if top_radius >= bottom_radius {
                    return Err(Error::InvalidInput(format!(
                        "cone: top radius {top_radius} must be smaller than bottom radius {bottom_radius}"
                    )));
                }
                b.set_size((2.0 * bottom_radius).max(height));
                b.frustum([0.0; 3], bottom_radius, top_radius, height);
                b.circle(CurveKind::Boundary, [0.0; 3], X, Y, bottom_radius);
                b.circle(CurveKind::Boundary, [0.0, 0.0, height], X, Y, top_radius);
            }
            Shape::Sphere { radius } => {
                positive("sphere radius", radius)?;
                b.set_size(2.0 * radius);
                b.patch(
                    Domain::Sphere {
                        center: [0.0; 3],
                        radius,
                        octant: None,
                    },
                    SurfaceParams::Sphere {
                        center: [0.0; 3],
                        radius,
                    },
                    Trim::None,
                    None,
                );
            }
            Shape::Torus {
                major_radius,
                minor_radius,
            } => {
                positive("torus major_radius", major_radius)?;
                positive("torus minor_radius", minor_radius)?;
                if minor_radius >= major_radius {
                    return Err(Error::InvalidInput(format!(
                        "torus: minor radius {minor_radius} must be smaller than major radius {major_radius}"
                    )));
                }
                b.set_size(2.0 * (major_radius + minor_radius));
                b.patch(
                    Domain::Torus {
                        center: [0.0; 3],
                        axis: Z,
                        e1: X,
                        e2: Y,
                        major: major_radius,
                        minor: minor_radius,
                    },
                    SurfaceParams::Torus {
                        center: [0.0; 3],
                        axis_dir: Z,
                        major_radius,
                        minor_radius,
                    },
                    Trim::None,
                    None,
                );
            }
        }
        let bbox = self.aabb();
        Ok(Model {
            patches: b.patches,
            curves: b.curves,
            bbox,
        })
    }

    /// Exact bounding box of the shape.
    pub fn aabb(&self) -> Aabb {
        let (min, max) = match *self {
            Shape::Cube { size } => ([-size / 2.0; 3], [size / 2.0; 3]),
            Shape::BoxWithHole { size, .. } => (scale(size, -0.5), scale(size, 0.5)),
            Shape::TwoCylinders {
                radius_a,
                half_length_a,
                half_length_b,
                ..
            } => (
                [-half_length_b, -radius_a, -half_length_a],
                [half_length_b, radius_a, half_length_a],
            ),
            Shape::RoundedCube { size, .. } => ([-size / 2.0; 3], [size / 2.0; 3]),
            Shape::FilletChamferCone {
                length,
                width,
                height,
                cone_height,
                ..
            } => (
                [-length / 2.0, -width / 2.0, 0.0],
                [length / 2.0, width / 2.0, height + cone_height],
            ),
            Shape::Plane { size } => (
                [-size / 2.0, -size / 2.0, 0.0],
                [size / 2.0, size / 2.0, 0.0],
            ),
            Shape::Cylinder { radius, height } => (
                [-radius, -radius, -height / 2.0],
                [radius, radius, height / 2.0],
            ),
            Shape::Cone {
                bottom_radius,
                height,
                ..
            } => (
                [-bottom_radius, -bottom_radius, 0.0],
                [bottom_radius, bottom_radius, height],
            ),
            Shape::Sphere { radius } => ([-radius; 3], [radius; 3]),
            Shape::Torus {
                major_radius,
                minor_radius,
            } => {
                let r = major_radius + minor_radius;
                ([-r, -r, -minor_radius], [r, r, minor_radius])
            }
        };
        Aabb { min, max }
    }
}

/// The exact description of a shape.
#[derive(Debug, Clone)]
pub(crate) struct Model {
    pub patches: Vec<Patch>,
    pub curves: Vec<FeatureCurve>,
    pub bbox: Aabb,
}

const X: Point3 = [1.0, 0.0, 0.0];
const Y: Point3 = [0.0, 1.0, 0.0];
const Z: Point3 = [0.0, 0.0, 1.0];

fn unit(k: usize, s: f64) -> Point3 {
    let mut v = [0.0; 3];
    v[k] = s;
    v
}

fn positive(what: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "{what} must be a positive finite number, got {v}"
        )))
    }
}

#[derive(Default)]
struct Builder {
    patches: Vec<Patch>,
    curves: Vec<FeatureCurve>,
    size: f64,
}

impl Builder {
    fn set_size(&mut self, size: f64) {
        self.size = size;
    }

    fn chord_error(&self) -> f64 {
        1e-4 * self.size
    }

    /// Adds a patch; its area is `area` or, if `None`, the untrimmed domain area.
    fn patch(&mut self, domain: Domain, params: SurfaceParams, trim: Trim, area: Option<f64>) {
        let area = area.unwrap_or_else(|| domain.area());
        let id = self.patches.len() as u32;
        self.patches.push(Patch {
            surface: Surface {
                id,
                kind: params.kind(),
                params,
                area,
            },
            domain,
            trim,
        });
    }

    /// A plane patch over the rectangle `origin + s u + t v`.
    #[allow(clippy::too_many_arguments)]
    fn plane_rect(
        &mut self,
        origin: Point3,
        u: Point3,
        v: Point3,
        s: [f64; 2],
        t: [f64; 2],
        normal: Point3,
        trim: Trim,
        area: Option<f64>,
    ) {
        let offset = dot(normal, origin);
        self.patch(
            Domain::Plane {
                origin,
                u,
                v,
                s,
                t,
                normal,
            },
            SurfaceParams::Plane { normal, offset },
            trim,
            area,
        );
    }

    fn segment(&mut self, kind: CurveKind, a: Point3, b: Point3) {
        let piece = self.size / 100.0;
        self.curves.push(FeatureCurve::segment(kind, a, b, piece));
    }

    #[allow(clippy::too_many_arguments)]
    fn arc(
        &mut self,
        kind: CurveKind,
        c: Point3,
        e1: Point3,
        e2: Point3,
        r: f64,
        start: f64,
        sweep: f64,
    ) {
        let e = self.chord_error();
        self.curves
            .push(FeatureCurve::arc(kind, c, e1, e2, r, start, sweep, e));
    }

    fn circle(&mut self, kind: CurveKind, c: Point3, e1: Point3, e2: Point3, r: f64) {
        self.arc(kind, c, e1, e2, r, 0.0, TAU);
    }

    /// The six faces of an axis-aligned box centred at the origin; with a hole of radius
    /// `hole` through the z faces.
    fn box_faces(&mut self, size: [f64; 3], hole: Option<f64>) {
        let h = scale(size, 0.5);
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            for s in [-1.0, 1.0] {
                let normal = unit(k, s);
                let origin = unit(k, s * h[k]);
                let (trim, area) = match hole {
                    Some(r) if k == 2 => (
                        Trim::Region(Region2 {
                            holes: vec![([0.0, 0.0], r)],
                            ..Default::default()
                        }),
                        Some(size[i] * size[j] - PI * r * r),
                    ),
                    _ => (Trim::None, None),
                };
                self.plane_rect(
                    origin,
                    unit(i, 1.0),
                    unit(j, 1.0),
                    [-h[i], h[i]],
                    [-h[j], h[j]],
                    normal,
                    trim,
                    area,
                );
            }
        }
    }

    /// The 12 sharp edges of an axis-aligned box centred at the origin.
    fn box_edges(&mut self, size: [f64; 3]) {
        let h = scale(size, 0.5);
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            for si in [-1.0, 1.0] {
                for sj in [-1.0, 1.0] {
                    let mut a = [0.0; 3];
                    a[i] = si * h[i];
                    a[j] = sj * h[j];
                    a[k] = -h[k];
                    let mut b = a;
                    b[k] = h[k];
                    self.segment(CurveKind::Sharp, a, b);
                }
            }
        }
    }

    /// A cone frustum around the axis z through `base` (radius r0 at base, r1 at base + height).
    fn frustum(&mut self, base: Point3, r0: f64, r1: f64, height: f64) {
        let half_angle = ((r0 - r1) / height).atan();
        let apex_h = height * r0 / (r0 - r1);
        let apex = [base[0], base[1], base[2] + apex_h];
        let axis = [0.0, 0.0, -1.0];
        let (e1, e2) = frame(axis);
        let sa = half_angle.sin();
        self.patch(
            Domain::Cone {
                apex,
                axis,
                e1,
                e2,
                half_angle,
                theta0: 0.0,
                sweep: TAU,
                l: [r1 / sa, r0 / sa],
            },
            SurfaceParams::Cone {
                apex,
                axis_dir: axis,
                half_angle,
            },
            Trim::None,
            Some(PI * (r0 + r1) * (r0 - r1).hypot(height)),
        );
    }
}

fn two_cylinders(b: &mut Builder, ra: f64, ha: f64, rb: f64, hb: f64) -> Result<()> {
    positive("two-cylinders radius_a", ra)?;
    positive("two-cylinders half_length_a", ha)?;
    positive("two-cylinders radius_b", rb)?;
    positive("two-cylinders half_length_b", hb)?;
    if rb >= ra || rb >= ha || ra >= hb {
        return Err(Error::InvalidInput(format!(
            "two-cylinders: need radius_b ({rb}) < radius_a ({ra}), radius_b < half_length_a ({ha}) \
             and radius_a < half_length_b ({hb}) so that B pierces A's side only"
        )));
    }
    b.set_size(2.0 * ha.max(hb).max(ra));
    // Area of A's side inside B: 2 × ∫_{-π/2}^{π/2} 2 rb² cos²t / sqrt(1 - k² sin²t) dt with
    // k = rb/ra (substitution sin θ = k sin t); periodic integrand: trapezoid rule is exact to
    // rounding with a few thousand nodes.
    let k = rb / ra;
    let inside_a = 2.0
        * periodic_integral(-FRAC_PI_2, FRAC_PI_2, |t| {
            2.0 * rb * rb * t.cos().powi(2) / (1.0 - k * k * t.sin().powi(2)).sqrt()
        });
    let x_int = move |phi: f64| (ra * ra - rb * rb * phi.cos().powi(2)).sqrt();
    // Each piece of B's side outside A: ∫_0^{2π} rb (hb - x_int(φ)) dφ.
    let b_piece = periodic_integral(0.0, TAU, |phi| rb * (hb - x_int(phi)));
    let trim_b = Trim::OutsideCylinder {
        axis_point: [0.0; 3],
        axis_dir: X,
        radius: rb,
    };
    let trim_a = Trim::OutsideCylinder {
        axis_point: [0.0; 3],
        axis_dir: Z,
        radius: ra,
    };
    // A's side.
    b.patch(
        Domain::Cylinder {
            center: [0.0; 3],
            axis: Z,
            e1: X,
            e2: Y,
            radius: ra,
            theta0: 0.0,
            sweep: TAU,
            h: [-ha, ha],
            inward: false,
        },
        SurfaceParams::Cylinder {
            axis_point: [0.0; 3],
            axis_dir: Z,
            radius: ra,
        },
        trim_b,
        Some(TAU * ra * 2.0 * ha - inside_a),
    );
    // A's caps.
    for s in [-1.0, 1.0] {
        b.plane_rect(
            [0.0, 0.0, s * ha],
            X,
            Y,
            [-ra, ra],
            [-ra, ra],
            [0.0, 0.0, s],
            Trim::Region(Region2 {
                disks: vec![([0.0, 0.0], ra)],
                ..Default::default()
            }),
            Some(PI * ra * ra),
        );
    }
    // B's side, two pieces (x < 0 and x > 0), the part inside A removed by the trim. The
    // domain starts at |x| = sqrt(ra² - rb²), the smallest |x| of the intersection curve.
    let x0 = (ra * ra - rb * rb).sqrt();
    for s in [-1.0, 1.0] {
        b.patch(
            Domain::Cylinder {
                center: [0.0; 3],
                axis: [s, 0.0, 0.0],
                e1: Y,
                e2: [0.0, 0.0, s],
                radius: rb,
                theta0: 0.0,
                sweep: TAU,
                h: [x0, hb],
                inward: false,
            },
            SurfaceParams::Cylinder {
                axis_point: [0.0; 3],
                axis_dir: X,
                radius: rb,
            },
            trim_a.clone(),
            Some(b_piece),
        );
    }
    // B's caps.
    for s in [-1.0, 1.0] {
        b.plane_rect(
            [s * hb, 0.0, 0.0],
            Y,
            Z,
            [-rb, rb],
            [-rb, rb],
            [s, 0.0, 0.0],
            Trim::Region(Region2 {
                disks: vec![([0.0, 0.0], rb)],
                ..Default::default()
            }),
            Some(PI * rb * rb),
        );
    }
    // Curves: the cap circles and the two intersection curves
    // (±x_int(φ), rb cos φ, rb sin φ). The polyline has 2^15 vertices per curve: its segments
    // are shorter than 2π·ra/2^15 ≈ 2e-4·size, so it deviates from the exact curve by at most
    // κ c²/8 < 1e-8·size (κ ≤ ra/rb² the largest curvature).
    for s in [-1.0, 1.0] {
        b.circle(CurveKind::Sharp, [0.0, 0.0, s * ha], X, Y, ra);
        b.circle(CurveKind::Sharp, [s * hb, 0.0, 0.0], Y, Z, rb);
    }
    const N: usize = 1 << 15;
    for s in [-1.0, 1.0] {
        let pts = (0..N)
            .map(|i| {
                let phi = TAU * i as f64 / N as f64;
                [s * x_int(phi), rb * phi.cos(), rb * phi.sin()]
            })
            .collect();
        b.curves
            .push(FeatureCurve::polyline(CurveKind::Sharp, pts, true));
    }
    Ok(())
}

/// Exact length of one cylinder–cylinder intersection curve of `Shape::TwoCylinders`, by
/// quadrature of |dP/dφ| (periodic integrand, trapezoid rule).
pub fn two_cylinders_curve_length(radius_a: f64, radius_b: f64) -> f64 {
    let (ra, rb) = (radius_a, radius_b);
    periodic_integral(0.0, TAU, |phi| {
        let (s, c) = phi.sin_cos();
        let x = (ra * ra - rb * rb * c * c).sqrt();
        let dx = rb * rb * c * s / x;
        (dx * dx + rb * rb).sqrt()
    })
}

/// Trapezoid rule over a full period of a smooth periodic integrand (exponential convergence).
fn periodic_integral(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    const N: usize = 8192;
    let h = (b - a) / N as f64;
    (0..N).map(|i| f(a + h * i as f64)).sum::<f64>() * h
}

/// Patch id of the rounded cube's plane face `(k, s)`, fillet `(k, si, sj)`, corner `(signs)`:
/// planes 0..6 (k·2 + side), fillets 6..18, corners 18..26. Used by the mesher too.
pub(crate) fn rounded_cube_plane_id(k: usize, s: f64) -> u32 {
    (k * 2 + usize::from(s > 0.0)) as u32
}

/// Fillet along axis k at the signs (si, sj) of the axes (k+1)%3, (k+2)%3.
pub(crate) fn rounded_cube_fillet_id(k: usize, si: f64, sj: f64) -> u32 {
    (6 + k * 4 + usize::from(si > 0.0) * 2 + usize::from(sj > 0.0)) as u32
}

/// Corner at the signs `s`.
pub(crate) fn rounded_cube_corner_id(s: [f64; 3]) -> u32 {
    (18 + usize::from(s[0] > 0.0) * 4 + usize::from(s[1] > 0.0) * 2 + usize::from(s[2] > 0.0))
        as u32
}

fn rounded_cube(b: &mut Builder, size: f64, r: f64) {
    let h = size / 2.0;
    let a = h - r;
    // Planes: ids 0..6.
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        for s in [-1.0, 1.0] {
            debug_assert_eq!(b.patches.len() as u32, rounded_cube_plane_id(k, s));
            b.plane_rect(
                unit(k, s * h),
                unit(i, 1.0),
                unit(j, 1.0),
                [-a, a],
                [-a, a],
                unit(k, s),
                Trim::None,
                None,
            );
        }
    }
    // Fillets: ids 6..18.
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        for si in [-1.0, 1.0] {
            for sj in [-1.0, 1.0] {
                debug_assert_eq!(b.patches.len() as u32, rounded_cube_fillet_id(k, si, sj));
                let mut center = [0.0; 3];
                center[i] = si * a;
                center[j] = sj * a;
                let e1 = unit(i, si);
                let e2 = unit(j, sj);
                b.patch(
                    Domain::Cylinder {
                        center,
                        axis: unit(k, 1.0),
                        e1,
                        e2,
                        radius: r,
                        theta0: 0.0,
                        sweep: FRAC_PI_2,
                        h: [-a, a],
                        inward: false,
                    },
                    SurfaceParams::Cylinder {
                        axis_point: center,
                        axis_dir: unit(k, 1.0),
                        radius: r,
                    },
                    Trim::None,
                    None,
                );
            }
        }
    }
    // Corners: ids 18..26.
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                let s = [sx, sy, sz];
                debug_assert_eq!(b.patches.len() as u32, rounded_cube_corner_id(s));
                let center = scale(s, a);
                b.patch(
                    Domain::Sphere {
                        center,
                        radius: r,
                        octant: Some(s),
                    },
                    SurfaceParams::Sphere { center, radius: r },
                    Trim::None,
                    None,
                );
            }
        }
    }
    // Smooth curves: plane / fillet borders and fillet / corner arcs.
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        for si in [-1.0, 1.0] {
            for sj in [-1.0, 1.0] {
                for on_i in [true, false] {
                    let mut p = [0.0; 3];
                    if on_i {
                        p[i] = si * h;
                        p[j] = sj * a;
                    } else {
                        p[i] = si * a;
                        p[j] = sj * h;
                    }
                    let mut q = p;
                    p[k] = -a;
                    q[k] = a;
                    b.segment(CurveKind::Smooth, p, q);
                }
                for sk in [-1.0, 1.0] {
                    let mut c = [0.0; 3];
                    c[i] = si * a;
                    c[j] = sj * a;
                    c[k] = sk * a;
                    b.arc(
                        CurveKind::Smooth,
                        c,
                        unit(i, si),
                        unit(j, sj),
                        r,
                        0.0,
                        FRAC_PI_2,
                    );
                }
            }
        }
    }
}

fn fillet_chamfer_cone(
    b: &mut Builder,
    [length, width, height]: [f64; 3],
    rf: f64,
    cf: f64,
    [rb, rt, hc]: [f64; 3],
) -> Result<()> {
    for (what, v) in [
        ("length", length),
        ("width", width),
        ("height", height),
        ("fillet_radius", rf),
        ("chamfer", cf),
        ("cone_base_radius", rb),
        ("cone_top_radius", rt),
        ("cone_height", hc),
    ] {
        positive(&format!("fillet-chamfer-cone {what}"), v)?;
    }
    let (l, w, hh) = (length / 2.0, width / 2.0, height);
    let top_w = width - rf - cf;
    if rf >= height || cf >= height || top_w <= 0.0 || rt >= rb || 2.0 * rb >= top_w.min(length) {
        return Err(Error::InvalidInput(format!(
            "fillet-chamfer-cone: need fillet radius ({rf}) and chamfer ({cf}) < height ({height}), \
             cone top radius ({rt}) < base radius ({rb}), and the cone base (diameter {}) inside \
             the top face ({length} × {top_w})",
            2.0 * rb
        )));
    }
    b.set_size(length.max(width).max(height + hc));
    let yc = (cf - rf) / 2.0;
    // Bottom.
    b.plane_rect(
        [0.0; 3],
        X,
        Y,
        [-l, l],
        [-w, w],
        [0.0, 0.0, -1.0],
        Trim::None,
        None,
    );
    // Top, minus the cone's base disk.
    b.plane_rect(
        [0.0, 0.0, hh],
        X,
        Y,
        [-l, l],
        [-w + cf, w - rf],
        Z,
        Trim::Region(Region2 {
            holes: vec![([0.0, yc], rb)],
            ..Default::default()
        }),
        Some(2.0 * l * top_w - PI * rb * rb),
    );
    // Long sides.
    b.plane_rect(
        [0.0, w, 0.0],
        X,
        Z,
        [-l, l],
        [0.0, hh - rf],
        Y,
        Trim::None,
        None,
    );
    b.plane_rect(
        [0.0, -w, 0.0],
        X,
        Z,
        [-l, l],
        [0.0, hh - cf],
        [0.0, -1.0, 0.0],
        Trim::None,
        None,
    );
    // End faces x = ±l, in (y, z) coordinates: the profile polygon ∪ the fillet quarter disk.
    let profile = vec![
        [-w, 0.0],
        [w, 0.0],
        [w, hh - rf],
        [w - rf, hh - rf],
        [w - rf, hh],
        [-w + cf, hh],
        [-w, hh - cf],
    ];
    let end_area = width * hh - cf * cf / 2.0 - rf * rf + PI * rf * rf / 4.0;
    for s in [-1.0, 1.0] {
        b.plane_rect(
            [s * l, 0.0, 0.0],
            Y,
            Z,
            [-w, w],
            [0.0, hh],
            [s, 0.0, 0.0],
            Trim::Region(Region2 {
                polygon: Some(profile.clone()),
                disks: vec![([w - rf, hh - rf], rf)],
                holes: vec![],
            }),
            Some(end_area),
        );
    }
    // Fillet.
    let fc = [0.0, w - rf, hh - rf];
    b.patch(
        Domain::Cylinder {
            center: fc,
            axis: X,
            e1: Y,
            e2: Z,
            radius: rf,
            theta0: 0.0,
            sweep: FRAC_PI_2,
            h: [-l, l],
            inward: false,
        },
        SurfaceParams::Cylinder {
            axis_point: fc,
            axis_dir: X,
            radius: rf,
        },
        Trim::None,
        None,
    );
    // Chamfer: from (y, z) = (-w, hh - cf) to (-w + cf, hh).
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    let cn = [0.0, -s2, s2];
    b.plane_rect(
        [0.0, -w, hh - cf],
        X,
        [0.0, s2, s2],
        [-l, l],
        [0.0, cf * std::f64::consts::SQRT_2],
        cn,
        Trim::None,
        None,
    );
    // Cone frustum and its flat top.
    b.frustum([0.0, yc, hh], rb, rt, hc);
    b.plane_rect(
        [0.0, yc, hh + hc],
        X,
        Y,
        [-rt, rt],
        [-rt, rt],
        Z,
        Trim::Region(Region2 {
            disks: vec![([0.0, 0.0], rt)],
            ..Default::default()
        }),
        Some(PI * rt * rt),
    );

    // Sharp curves.
    let sharp = CurveKind::Sharp;
    let c = [[-l, -w, 0.0], [l, -w, 0.0], [l, w, 0.0], [-l, w, 0.0]];
    for i in 0..4 {
        b.segment(sharp, c[i], c[(i + 1) % 4]);
    }
    for s in [-1.0, 1.0] {
        let x = s * l;
        b.segment(sharp, [x, w, 0.0], [x, w, hh - rf]);
        b.segment(sharp, [x, -w, 0.0], [x, -w, hh - cf]);
        b.segment(sharp, [x, -w + cf, hh], [x, w - rf, hh]);
        b.segment(sharp, [x, -w, hh - cf], [x, -w + cf, hh]);
        b.arc(sharp, [x, w - rf, hh - rf], Y, Z, rf, 0.0, FRAC_PI_2);
    }
    b.segment(sharp, [-l, -w + cf, hh], [l, -w + cf, hh]);
    b.segment(sharp, [-l, -w, hh - cf], [l, -w, hh - cf]);
    b.circle(sharp, [0.0, yc, hh], X, Y, rb);
    b.circle(sharp, [0.0, yc, hh + hc], X, Y, rt);
    // Smooth curves: the fillet borders.
    b.segment(CurveKind::Smooth, [-l, w - rf, hh], [l, w - rf, hh]);
    b.segment(CurveKind::Smooth, [-l, w, hh - rf], [l, w, hh - rf]);
    Ok(())
}
