//! PNG quick-looks: pixels where the geometry projects, z-buffer order, colourings, legend,
//! polylines, the bitmap font, PNG output, bad input.

use crate::common;

use std::collections::HashMap;

use crease::render::colormap::{self, viridis, FLAG_OFF, FLAG_ON};
use crease::render::font;
use crease::render::{
    render, render_png, ColorBy, Polyline, RenderParams, Scene, View, ViewLayout,
};
use crease::{Attribute, PointCloud, TriMesh};
use tiny_skia::Pixmap;

const WHITE: [u8; 3] = [255, 255, 255];

/// Saves `img` under the temp dir when `CREASE_RENDER_DUMP` is set (for looking at failures).
fn dump(img: &Pixmap, name: &str) {
    if std::env::var_os("CREASE_RENDER_DUMP").is_some() {
        let p = std::env::temp_dir().join(format!("crease-render-{name}.png"));
        img.save_png(&p).unwrap();
    }
}

fn px(img: &Pixmap, x: u32, y: u32) -> [u8; 3] {
    let p = img.pixel(x, y).expect("pixel inside");
    [p.red(), p.green(), p.blue()]
}

/// Bounding box (x0, y0, x1, y1) of the pixels of exactly `c`.
fn bbox_of(img: &Pixmap, c: [u8; 3]) -> Option<(u32, u32, u32, u32)> {
    bbox_left_of(img, c, img.width())
}

/// Bounding box of the pixels of exactly `c` left of column `xmax`.
fn bbox_left_of(img: &Pixmap, c: [u8; 3], xmax: u32) -> Option<(u32, u32, u32, u32)> {
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for y in 0..img.height() {
        for x in 0..xmax.min(img.width()) {
            if px(img, x, y) == c {
                b = Some(match b {
                    None => (x, y, x, y),
                    Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
                });
            }
        }
    }
    b
}

fn histogram(img: &Pixmap, x0: u32, y0: u32, x1: u32, y1: u32) -> HashMap<[u8; 3], usize> {
    let mut h = HashMap::new();
    for y in y0..=y1.min(img.height() - 1) {
        for x in x0..=x1.min(img.width() - 1) {
            *h.entry(px(img, x, y)).or_insert(0) += 1;
        }
    }
    h
}

/// An n × n grid on the square [x0, x0 + s] × [z0, z0 + s] at depth y (parallel to XZ).
fn square_xz(n: usize, x0: f64, z0: f64, s: f64, y: f64) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let u = i as f64 / (n - 1) as f64;
            let w = j as f64 / (n - 1) as f64;
            v.push([x0 + s * u, y, z0 + s * w]);
        }
    }
    v
}

/// An n × n grid on the unit square of the plane z = 0.
fn plane_xy(n: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for j in 0..n {
        for i in 0..n {
            v.push([i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64, 0.0]);
        }
    }
    v
}

/// Points on the faces of the cube [-1, 1]^3, `n` × `n` per face, flagged sharp within
/// `band` of an edge (two coordinates near ±1).
fn cube_points(n: usize, band: f64) -> PointCloud {
    let mut pts = Vec::new();
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            for i in 0..n {
                for j in 0..n {
                    let u = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
                    let v = -1.0 + 2.0 * j as f64 / (n - 1) as f64;
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    pts.push(p);
                }
            }
        }
    }
    let sharp: Vec<bool> = pts
        .iter()
        .map(|p: &[f64; 3]| p.iter().filter(|c| c.abs() > 1.0 - band).count() >= 2)
        .collect();
    let mut cloud = PointCloud::from_positions(pts);
    cloud
        .set_attribute(Attribute::flag("sharp", sharp))
        .unwrap();
    cloud
}

/// The 12 edges of the cube [-1, 1]^3.
fn cube_edges(color: [u8; 3], label: &str) -> Vec<Polyline> {
    let mut out = Vec::new();
    for axis in 0..3 {
        for a in [-1.0, 1.0] {
            for b in [-1.0, 1.0] {
                let mut p = [0.0; 3];
                let mut q = [0.0; 3];
                p[axis] = -1.0;
                q[axis] = 1.0;
                p[(axis + 1) % 3] = a;
                q[(axis + 1) % 3] = a;
                p[(axis + 2) % 3] = b;
                q[(axis + 2) % 3] = b;
                out.push(Polyline {
                    points: vec![p, q],
                    closed: false,
                    color,
                    label: Some(label.to_string()),
                });
            }
        }
    }
    out
}

fn cube_mesh() -> TriMesh {
    let v: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            ]
        })
        .collect();
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
    TriMesh::new(v, f).unwrap()
}

fn single(view: View, w: u32, h: u32, color_by: ColorBy, legend: bool) -> RenderParams {
    RenderParams {
        width: w,
        height: h,
        layout: ViewLayout::Single(view),
        color_by,
        legend,
        ..Default::default()
    }
}

#[test]
fn red_plane_seen_from_top_fills_its_square() {
    let mut cloud = PointCloud::from_positions(plane_xy(120));
    cloud.set_colors(vec![[255, 0, 0]; cloud.len()]).unwrap();
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    let img = render(&scene, &single(View::Top, 800, 600, ColorBy::Rgb, false)).unwrap();
    dump(&img, "1");
    let (x0, y0, x1, y1) = bbox_of(&img, [255, 0, 0]).expect("red pixels");
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    // The square fills most of the view's height and is square (orthographic, same scale).
    assert!(h > 400, "projected square is {w} x {h}");
    assert!(w.abs_diff(h) <= 2, "projected square is {w} x {h}");
    // Its interior is entirely point colour.
    let m = w / 20;
    let hist = histogram(&img, x0 + m, y0 + m, x1 - m, y1 - m);
    assert_eq!(hist.len(), 1, "interior colours: {hist:?}");
    // The image corners and the band around the square are background.
    for (x, y) in [(0, 0), (799, 0), (0, 599), (799, 599)] {
        assert_eq!(px(&img, x, y), WHITE);
    }
    assert_eq!(px(&img, x1 + 8, (y0 + y1) / 2), WHITE);
    assert_eq!(px(&img, (x0 + x1) / 2, y0 - 8), WHITE);
}

#[test]
fn nearer_square_hides_farther_one() {
    const BLUE: [u8; 3] = [0, 0, 255];
    const RED: [u8; 3] = [255, 0, 0];
    // Near square (y = 0) on x in [0, 2]; far square (y = 1) on x in [1, 3]. The front view
    // looks toward +Y, so the near one must win on x in [1, 2] whatever the drawing order.
    for near_first in [true, false] {
        let near = square_xz(80, 0.0, 0.0, 2.0, 0.0);
        let far = square_xz(80, 1.0, 0.0, 2.0, 1.0);
        let (a, b, ca, cb) = if near_first {
            (near, far, BLUE, RED)
        } else {
            (far, near, RED, BLUE)
        };
        let mut colors = vec![ca; a.len()];
        colors.extend(vec![cb; b.len()]);
        let mut pos = a;
        pos.extend(b);
        let mut cloud = PointCloud::from_positions(pos);
        cloud.set_colors(colors).unwrap();
        let scene = Scene {
            points: Some(&cloud),
            ..Default::default()
        };
        let img = render(&scene, &single(View::Front, 900, 500, ColorBy::Rgb, false)).unwrap();
        dump(&img, "2");
        let (bx0, by0, bx1, by1) = bbox_of(&img, BLUE).unwrap();
        let (rx0, _, rx1, _) = bbox_of(&img, RED).unwrap();
        let (x0, x1) = (bx0.min(rx0), bx1.max(rx1));
        let span = f64::from(x1 - x0);
        let ym = (by0 + by1) / 2;
        let at = |f: f64| px(&img, x0 + (span * f).round() as u32, ym);
        assert_eq!(at(1.0 / 6.0), BLUE, "near_first={near_first}");
        assert_eq!(at(0.5), BLUE, "overlap, near_first={near_first}");
        assert_eq!(at(0.45), BLUE, "overlap, near_first={near_first}");
        assert_eq!(at(0.55), BLUE, "overlap, near_first={near_first}");
        assert_eq!(at(5.0 / 6.0), RED, "near_first={near_first}");
    }
}

#[test]
fn nearer_triangles_hide_farther_ones() {
    // Two quads facing the front view, the near one labelled 0, the far one 1.
    let quad = |x0: f64, y: f64| -> Vec<[f64; 3]> {
        vec![
            [x0, y, 0.0],
            [x0 + 2.0, y, 0.0],
            [x0 + 2.0, y, 2.0],
            [x0, y, 2.0],
        ]
    };
    let mut v = quad(1.0, 1.0); // far, drawn first
    v.extend(quad(0.0, 0.0)); // near
    let faces = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    let mut mesh = TriMesh::new(v, faces).unwrap();
    mesh.set_face_attribute(Attribute::int("part", [2, 2, 1, 1]))
        .unwrap();
    let scene = Scene {
        mesh: Some(&mesh),
        ..Default::default()
    };
    let params = single(
        View::Front,
        900,
        500,
        ColorBy::Attribute("part".into()),
        false,
    );
    let img = render(&scene, &params).unwrap();
    dump(&img, "3");
    // Both quads face the camera: same light, so each has one colour; part 1 is palette blue,
    // part 2 palette orange.
    let hist = histogram(&img, 0, 0, 899, 499);
    let mut big: Vec<([u8; 3], usize)> = hist
        .into_iter()
        .filter(|(c, n)| *n > 5000 && *c != WHITE)
        .collect();
    big.sort_by_key(|b| std::cmp::Reverse(b.1));
    assert_eq!(big.len(), 2, "{big:?}");
    let bluish = big.iter().find(|(c, _)| c[2] > c[0]).unwrap().0;
    let orange = big.iter().find(|(c, _)| c[0] > c[2]).unwrap().0;
    let (bx0, by0, bx1, by1) = bbox_of(&img, bluish).unwrap();
    let (_, _, ox1, _) = bbox_of(&img, orange).unwrap();
    let span = f64::from(ox1 - bx0);
    let ym = (by0 + by1) / 2;
    assert_eq!(px(&img, bx0 + (span * 0.5) as u32, ym), bluish);
    assert_eq!(px(&img, bx0 + (span * 0.6) as u32, ym), bluish);
    assert_eq!(px(&img, bx0 + (span * 0.85) as u32, ym), orange);
    // The near quad spans 2/3 of the total width.
    let near_w = f64::from(bx1 - bx0);
    assert!(
        (near_w / span - 2.0 / 3.0).abs() < 0.02,
        "{near_w} / {span}"
    );
}

#[test]
fn flag_attribute_gives_two_point_colours_and_a_legend() {
    let cloud = cube_points(60, 0.1);
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    let params = single(
        View::Iso,
        1200,
        800,
        ColorBy::Attribute("sharp".into()),
        true,
    );
    let img = render(&scene, &params).unwrap();
    dump(&img, "4");
    // The legend (at most a third of the width) is on the right: look left of it. The grey
    // (not sharp) points span the cube's drawing but for the red band along its outline.
    let (ox0, oy0, ox1, oy1) = bbox_left_of(&img, FLAG_OFF, 800).expect("grey points");
    assert!(ox1 < 780 && ox1 - ox0 > 300, "drawing spans {ox0}..{ox1}");
    // Within the drawing of the cube, only background and the two flag colours.
    let hist = histogram(&img, ox0, oy0, ox1, oy1);
    assert!(
        hist.keys()
            .all(|c| *c == WHITE || *c == FLAG_OFF || *c == FLAG_ON),
        "{hist:?}"
    );
    assert!(
        hist[&FLAG_OFF] > 10_000 && hist[&FLAG_ON] > 2_000,
        "{hist:?}"
    );
    // The legend (right of the drawing) has dark text and the two swatches.
    let legend_x0 = ox1 + 40;
    let legend = histogram(&img, legend_x0, 0, 1199, 799);
    let text = legend
        .iter()
        .filter(|(c, _)| c[0] < 100 && c[0] == c[1] && c[1] == c[2])
        .map(|e| e.1)
        .sum::<usize>();
    assert!(text > 300, "legend text pixels: {text}");
    assert!(legend.get(&FLAG_ON).copied().unwrap_or(0) > 50);
    assert!(legend.get(&FLAG_OFF).copied().unwrap_or(0) > 50);
    // Without a legend, that area holds no text.
    let params = RenderParams {
        legend: false,
        ..params
    };
    let img = render(&scene, &params).unwrap();
    dump(&img, "5");
    let legend = histogram(&img, legend_x0, 0, 1199, 799);
    let text = legend
        .iter()
        .filter(|(c, _)| c[0] < 100 && c[0] == c[1] && c[1] == c[2])
        .count();
    assert_eq!(text, 0);
}

#[test]
fn float_attribute_maps_min_and_max_to_viridis_ends() {
    let pos = plane_xy(100);
    let values: Vec<f64> = pos.iter().map(|p| 3.0 + 4.0 * p[0]).collect();
    let mut cloud = PointCloud::from_positions(pos);
    cloud
        .set_attribute(Attribute::float("sharpness", values))
        .unwrap();
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    let params = single(
        View::Top,
        1000,
        700,
        ColorBy::Attribute("sharpness".into()),
        true,
    );
    let img = render(&scene, &params).unwrap();
    dump(&img, "6");
    let first = viridis(0.0);
    let last = viridis(1.0);
    assert_eq!(first, [68, 1, 84]);
    assert_eq!(last, [253, 231, 37]);
    let (fx0, fy0, _, fy1) = bbox_of(&img, first).expect("min-value colour");
    let (lx0, _, _, _) = bbox_of(&img, last).expect("max-value colour");
    // Min-value points (x = 0) are on the left edge of the square, max-value on the right.
    assert!(fx0 < lx0, "first colour at {fx0}, last at {lx0}");
    let ym = (fy0 + fy1) / 2;
    // Pixel column of the leftmost points: the first colour; middle: neither end.
    assert_eq!(px(&img, fx0 + 1, ym), first);
    // The colour bar (in the legend, right) also holds both ends; along the middle row of the
    // square the first last-colour pixel is the square's right edge.
    let row_last: Vec<u32> = (0..img.width())
        .filter(|&x| px(&img, x, ym) == last)
        .collect();
    assert!(!row_last.is_empty(), "max colour on the middle row");
    let row_first: Vec<u32> = (0..img.width())
        .filter(|&x| px(&img, x, ym) == first)
        .collect();
    let mid = (row_first[0] + row_last[0]) / 2;
    let c = px(&img, mid, ym);
    assert!(c != first && c != last && c != WHITE, "{c:?}");
    // And it is the viridis colour of the middle value.
    let want = viridis(0.5);
    let d: i32 = (0..3)
        .map(|k| (i32::from(c[k]) - i32::from(want[k])).abs())
        .sum();
    assert!(d < 30, "middle {c:?} vs viridis(0.5) {want:?}");
}

#[test]
fn many_cluster_ids_get_hashed_colours() {
    let pos = plane_xy(60);
    let ids: Vec<i64> = pos
        .iter()
        .map(|p| (p[0] * 9.99) as i64 * 10 + (p[1] * 9.99) as i64)
        .collect();
    let mut cloud = PointCloud::from_positions(pos);
    cloud.set_attribute(Attribute::int("cluster", ids)).unwrap();
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    let params = single(
        View::Top,
        800,
        600,
        ColorBy::Attribute("cluster".into()),
        true,
    );
    let img = render(&scene, &params).unwrap();
    dump(&img, "7");
    let hist = histogram(&img, 0, 0, 799, 599);
    let blocks = hist.iter().filter(|(_, n)| **n > 800).count();
    // 100 clusters of about 36 x 36 px each, most with their own colour.
    assert!(blocks > 60, "{blocks} large colour areas");
    assert_eq!(colormap::hashed_color(7), colormap::hashed_color(7));
}

#[test]
fn mesh_cube_shows_three_shades_in_iso_view() {
    let mesh = cube_mesh();
    let scene = Scene {
        mesh: Some(&mesh),
        ..Default::default()
    };
    let img = render(
        &scene,
        &single(View::Iso, 800, 600, ColorBy::Uniform, false),
    )
    .unwrap();
    dump(&img, "8");
    let hist = histogram(&img, 0, 0, 799, 599);
    let mut faces: Vec<[u8; 3]> = hist
        .iter()
        .filter(|(c, n)| **n > 10_000 && **c != WHITE)
        .map(|(c, _)| *c)
        .collect();
    faces.sort();
    assert_eq!(faces.len(), 3, "{faces:?}");
    let lum = |c: [u8; 3]| 0.3 * f64::from(c[0]) + 0.59 * f64::from(c[1]) + 0.11 * f64::from(c[2]);
    for i in 0..3 {
        for j in i + 1..3 {
            assert!((lum(faces[i]) - lum(faces[j])).abs() > 10.0, "{faces:?}");
        }
    }
}

#[test]
fn polyline_colour_lies_along_its_path() {
    const GREEN: [u8; 3] = [0, 140, 60];
    let scene = Scene {
        polylines: vec![Polyline {
            points: vec![[0.0, 0.0, 0.0], [1.0, 0.6, 0.0], [2.0, 1.0, 0.0]],
            closed: false,
            color: GREEN,
            label: None,
        }],
        ..Default::default()
    };
    let img = render(
        &scene,
        &single(View::Top, 800, 600, ColorBy::Uniform, false),
    )
    .unwrap();
    dump(&img, "9");
    let (x0, _, x1, y1) = bbox_of(&img, GREEN).expect("line pixels");
    assert!(x1 - x0 > 500, "line spans {x0}..{x1}");
    // Walk both segments: in world x = 0 .. 2 the image x is linear, y follows the polyline.
    let sx = f64::from(x1 - x0) / 2.0;
    let world_to_px = |wx: f64, wy: f64| -> (u32, u32) {
        let x = f64::from(x0) + wx * sx;
        let y = f64::from(y1) - wy * sx;
        (x.round() as u32, y.round() as u32)
    };
    for k in 1..40 {
        let wx = 2.0 * f64::from(k) / 40.0;
        let wy = if wx <= 1.0 {
            0.6 * wx
        } else {
            0.6 + 0.4 * (wx - 1.0)
        };
        let (x, y) = world_to_px(wx, wy);
        let near = (y.saturating_sub(2)..=y + 2).any(|yy| px(&img, x, yy) == GREEN);
        assert!(near, "no line colour near ({x}, {y}) for world x {wx}");
    }
    // Far from the line: background.
    let (x, y) = world_to_px(1.5, 0.2);
    assert_eq!(px(&img, x, y), WHITE);
}

#[test]
fn polylines_behind_a_surface_are_faint() {
    // A square plate z = 0 seen from the top; one line just above it, one below it.
    let mesh = TriMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    const RED: [u8; 3] = [220, 0, 0];
    const BLUE: [u8; 3] = [0, 0, 220];
    let scene = Scene {
        mesh: Some(&mesh),
        polylines: vec![
            Polyline {
                points: vec![[0.1, 0.3, 0.0], [0.9, 0.3, 0.0]],
                closed: false,
                color: RED,
                label: Some("on top".into()),
            },
            Polyline {
                points: vec![[0.1, 0.7, -0.5], [0.9, 0.7, -0.5]],
                closed: false,
                color: BLUE,
                label: Some("below".into()),
            },
        ],
        ..Default::default()
    };
    let img = render(
        &scene,
        &single(View::Top, 800, 600, ColorBy::Uniform, false),
    )
    .unwrap();
    dump(&img, "10");
    assert!(
        bbox_of(&img, RED).is_some(),
        "visible line drawn in full colour"
    );
    assert!(
        bbox_of(&img, BLUE).is_none(),
        "hidden line must not be drawn in full colour"
    );
    // But it is there, faintly: a bluish tint along its path.
    let hist = histogram(&img, 0, 0, 799, 599);
    let tinted = hist
        .iter()
        .filter(|(c, _)| u16::from(c[2]) > u16::from(c[0]) + 20)
        .map(|e| e.1)
        .sum::<usize>();
    assert!(tinted > 300, "faint hidden line pixels: {tinted}");
}

#[test]
fn every_printable_glyph_has_ink() {
    let mut seen = std::collections::HashSet::new();
    for code in 32u8..=126 {
        let c = code as char;
        let n: usize = (0..font::GLYPH_W)
            .flat_map(|x| (0..font::GLYPH_H).map(move |y| (x, y)))
            .filter(|&(x, y)| font::pixel_set(c, x, y))
            .count();
        if c == ' ' {
            assert_eq!(n, 0);
        } else {
            assert!(n > 0, "glyph {c:?} is empty");
            assert!(
                seen.insert(font::glyph(c)),
                "glyph {c:?} duplicates another"
            );
        }
    }
    assert_eq!(font::text_width("abc", 2), (3 * font::ADVANCE - 1) * 2);
}

#[test]
fn png_file_round_trips() {
    let cloud = cube_points(20, 0.1);
    let scene = Scene {
        points: Some(&cloud),
        polylines: cube_edges([31, 119, 180], "edge"),
        ..Default::default()
    };
    let params = RenderParams {
        width: 640,
        height: 480,
        color_by: ColorBy::Attribute("sharp".into()),
        title: Some("cube".into()),
        ..Default::default()
    };
    let dir = common::tempdir();
    let path = dir.path().join("cube.png");
    render_png(&scene, &params, &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let back = Pixmap::load_png(&path).unwrap();
    assert_eq!((back.width(), back.height()), (640, 480));
    let direct = render(&scene, &params).unwrap();
    assert_eq!(back.data(), direct.data());
    // A path in a missing directory: the error names the file.
    let bad = dir.path().join("missing").join("x.png");
    let err = render_png(&scene, &params, &bad).unwrap_err().to_string();
    assert!(err.contains("x.png"), "{err}");
}

#[test]
fn bad_input_gives_errors_not_panics() {
    let params = RenderParams::default();
    // Empty scene.
    assert!(render(&Scene::default(), &params).is_err());
    let empty = PointCloud::default();
    assert!(render(
        &Scene {
            points: Some(&empty),
            ..Default::default()
        },
        &params
    )
    .is_err());
    // Only NaN positions.
    let nan = PointCloud::from_positions(vec![[f64::NAN, 0.0, 0.0]; 10]);
    assert!(render(
        &Scene {
            points: Some(&nan),
            ..Default::default()
        },
        &params
    )
    .is_err());
    // Missing attribute: the message lists what exists.
    let mut cloud = PointCloud::from_positions(plane_xy(10));
    cloud
        .set_attribute(Attribute::float("sharpness", vec![0.0; 100]))
        .unwrap();
    cloud
        .set_attribute(Attribute::int("cluster", vec![1; 100]))
        .unwrap();
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    let p = RenderParams {
        color_by: ColorBy::Attribute("nope".into()),
        ..Default::default()
    };
    let err = render(&scene, &p).unwrap_err().to_string();
    assert!(
        err.contains("nope") && err.contains("sharpness") && err.contains("cluster"),
        "{err}"
    );
    // Rgb / Normal without the data.
    for c in [ColorBy::Rgb, ColorBy::Normal] {
        let p = RenderParams {
            color_by: c,
            ..Default::default()
        };
        assert!(render(&scene, &p).is_err());
    }
    // Absurd sizes.
    for (w, h) in [(0, 100), (100, 0), (100_000, 100)] {
        let p = RenderParams {
            width: w,
            height: h,
            ..Default::default()
        };
        assert!(render(&scene, &p).is_err());
    }
    // A face pointing past the vertices.
    let mesh = TriMesh {
        vertices: PointCloud::from_positions(vec![[0.0; 3]; 3]),
        faces: vec![[0, 1, 7]],
        ..Default::default()
    };
    assert!(render(
        &Scene {
            mesh: Some(&mesh),
            ..Default::default()
        },
        &params
    )
    .is_err());
}

#[test]
fn degenerate_scenes_render() {
    const RED: [u8; 3] = [255, 0, 0];
    // A single point (zero extent), with NaN points around it.
    let mut cloud = PointCloud::from_positions(vec![
        [f64::NAN; 3],
        [1.0, 2.0, 3.0],
        [0.0, f64::INFINITY, 0.0],
    ]);
    cloud.set_colors(vec![RED; 3]).unwrap();
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    let params = RenderParams {
        width: 800,
        height: 600,
        color_by: ColorBy::Rgb,
        ..Default::default()
    };
    let img = render(&scene, &params).unwrap();
    dump(&img, "11");
    assert!(
        bbox_of(&img, RED).is_some(),
        "the one finite point is drawn"
    );
    // A flat plane seen edge-on in the front view: a line of pixels, no division by zero.
    let mut plane = PointCloud::from_positions(plane_xy(30));
    plane.set_colors(vec![RED; plane.len()]).unwrap();
    let scene = Scene {
        points: Some(&plane),
        ..Default::default()
    };
    let img = render(&scene, &single(View::Front, 800, 600, ColorBy::Rgb, false)).unwrap();
    dump(&img, "12");
    let (x0, y0, x1, y1) = bbox_of(&img, RED).unwrap();
    assert!(x1 - x0 > 300 && y1 - y0 < 20, "{x0} {y0} {x1} {y1}");
    // Four views of it too.
    let img = render(&scene, &params).unwrap();
    dump(&img, "13");
    assert!(bbox_of(&img, RED).is_some());
}

#[test]
fn output_is_deterministic_across_thread_counts() {
    let cloud = cube_points(40, 0.1);
    let scene = Scene {
        points: Some(&cloud),
        polylines: cube_edges([31, 119, 180], "edge"),
        ..Default::default()
    };
    let params = RenderParams {
        width: 800,
        height: 600,
        color_by: ColorBy::Attribute("sharp".into()),
        ..Default::default()
    };
    let a = render(&scene, &params).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(|| render(&scene, &params).unwrap());
    assert_eq!(a.data(), b.data());
}

/// Writes a sample image for eyeballing:
/// `cargo test -p crease --test it -- --ignored render::demo`.
#[test]
#[ignore]
fn demo_image() {
    let cloud = cube_points(90, 0.06);
    let scene = Scene {
        points: Some(&cloud),
        polylines: cube_edges(crease::render::SMOOTH_LINE, "sharp edge"),
        ..Default::default()
    };
    let params = RenderParams {
        color_by: ColorBy::Attribute("sharp".into()),
        title: Some("cube: sharp points and feature lines".into()),
        ..Default::default()
    };
    let path = std::env::temp_dir().join("crease-render-demo.png");
    render_png(&scene, &params, &path).unwrap();
    eprintln!("wrote {}", path.display());
}

/// Render times at 100k and 1M points (four views, coloured by a flag, with the cube's
/// edges): `cargo test --release -p crease --test it -- --ignored render::timing --nocapture`.
#[test]
#[ignore]
fn timing() {
    for n in [129, 408] {
        let cloud = cube_points(n, 0.05);
        let scene = Scene {
            points: Some(&cloud),
            polylines: cube_edges(crease::render::SMOOTH_LINE, "edge"),
            ..Default::default()
        };
        let params = RenderParams {
            color_by: ColorBy::Attribute("sharp".into()),
            ..Default::default()
        };
        let _ = render(&scene, &params).unwrap();
        let t = std::time::Instant::now();
        let reps = 3;
        for _ in 0..reps {
            let _ = render(&scene, &params).unwrap();
        }
        let dt = t.elapsed().as_secs_f64() / f64::from(reps);
        let t = std::time::Instant::now();
        let img = render(&scene, &params).unwrap();
        let _png = img.encode_png().unwrap();
        let dt_png = t.elapsed().as_secs_f64();
        eprintln!(
            "{} points: render {:.3} s, render + PNG encode {:.3} s ({} threads)",
            cloud.len(),
            dt,
            dt_png,
            rayon::current_num_threads()
        );
    }
}

/// Reads the shared-data OFF mesh (demo only; the library's reader lives in `io`).
fn read_off(path: &std::path::Path) -> TriMesh {
    let text = std::fs::read_to_string(path).unwrap();
    let mut it = text.split_whitespace();
    assert_eq!(it.next(), Some("OFF"));
    let nv: usize = it.next().unwrap().parse().unwrap();
    let nf: usize = it.next().unwrap().parse().unwrap();
    let _ne = it.next();
    let mut num = || -> f64 { it.next().unwrap().parse().unwrap() };
    let v: Vec<[f64; 3]> = (0..nv).map(|_| [num(), num(), num()]).collect();
    let mut f = Vec::new();
    for _ in 0..nf {
        let k = num() as usize;
        let ids: Vec<u32> = (0..k).map(|_| num() as u32).collect();
        for j in 1..k - 1 {
            f.push([ids[0], ids[j], ids[j + 1]]);
        }
    }
    TriMesh::new(v, f).unwrap()
}

/// Reads a PCEDNet PLY (x y z nx ny nz as float, r g b a as uchar): the cloud with normals
/// and a `gt_sharp` flag from the class colour (demo only).
fn read_pcednet(path: &std::path::Path) -> PointCloud {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    let n: usize = header
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let mut pos = Vec::with_capacity(n);
    let mut nor = Vec::with_capacity(n);
    let mut sharp = Vec::with_capacity(n);
    for i in 0..n {
        let r = &bytes[end + 28 * i..end + 28 * (i + 1)];
        let f = |k: usize| {
            f64::from(f32::from_le_bytes([
                r[4 * k],
                r[4 * k + 1],
                r[4 * k + 2],
                r[4 * k + 3],
            ]))
        };
        pos.push([f(0), f(1), f(2)]);
        nor.push([f(3), f(4), f(5)]);
        sharp.push(r[24] > 0 && r[25] == 0 && r[26] == 0);
    }
    let mut c = PointCloud::from_positions(pos);
    c.set_normals(nor).unwrap();
    c.set_attribute(Attribute::flag("gt_sharp", sharp)).unwrap();
    c
}

/// Sample images from the shared data, for eyeballing:
/// `cargo test -p crease --test it -- --ignored render::demo_real`.
#[test]
#[ignore]
fn demo_real_data() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    // Fandisk: shaded mesh and its edges with a dihedral angle above 30 degrees.
    let mesh = read_off(&dir.join("meshes/fandisk.off"));
    let mut edges: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (fi, f) in mesh.faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(fi);
        }
    }
    let normal = |fi: usize| {
        let [a, b, c] = mesh.triangle(fi);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        [n[0] / l, n[1] / l, n[2] / l]
    };
    let mut keys: Vec<_> = edges.keys().copied().collect();
    keys.sort();
    let mut lines = Vec::new();
    for (a, b) in keys {
        let fs = &edges[&(a, b)];
        if fs.len() == 2 {
            let (n0, n1) = (normal(fs[0]), normal(fs[1]));
            let c = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2];
            if c < 30f64.to_radians().cos() {
                lines.push(Polyline {
                    points: vec![mesh.positions()[a as usize], mesh.positions()[b as usize]],
                    closed: false,
                    color: crease::render::SHARP_LINE,
                    label: Some("sharp edge".into()),
                });
            }
        }
    }
    let scene = Scene {
        mesh: Some(&mesh),
        polylines: lines,
        ..Default::default()
    };
    let params = RenderParams {
        title: Some("fandisk: dihedral angle > 30 deg".into()),
        ..Default::default()
    };
    let out = std::env::temp_dir().join("crease-render-fandisk.png");
    render_png(&scene, &params, &out).unwrap();
    eprintln!("wrote {}", out.display());
    // A PCEDNet ABC cloud coloured by its ground-truth sharp flag, and lit (uniform).
    let cloud = read_pcednet(&dir.join("points-gt/abc/0133.ply"));
    let scene = Scene {
        points: Some(&cloud),
        ..Default::default()
    };
    for (name, color_by) in [
        ("gt", ColorBy::Attribute("gt_sharp".into())),
        ("lit", ColorBy::Uniform),
        ("normal", ColorBy::Normal),
    ] {
        let params = RenderParams {
            title: Some(format!("ABC 0133 ({name})")),
            color_by,
            ..Default::default()
        };
        let out = std::env::temp_dir().join(format!("crease-render-abc-{name}.png"));
        render_png(&scene, &params, &out).unwrap();
        eprintln!("wrote {}", out.display());
    }
}

/// The HTML view (`crease::render::html`): a 1M-point cloud with `crease run`'s six labels fits
/// in 40 MB; above `max_points` an even subsample is embedded and the page says how many of how
/// many; the page holds no reference to the network.
#[test]
fn html_view_size_and_subsample() {
    use crease::render::html::{page, PageParams};
    use crease::render::Scene;
    use crease::{Attribute, PointCloud};
    let n = 1_000_000;
    let mut cloud = PointCloud::from_positions(
        (0..n)
            .map(|i| {
                let t = i as f64 * 0.618_033_988_75;
                [t.fract(), (t * 7.0).fract(), (i % 1000) as f64 * 1e-3]
            })
            .collect(),
    );
    cloud
        .set_attribute(Attribute::flag("sharp", (0..n).map(|i| i % 13 == 0)))
        .expect("sharp");
    cloud
        .set_attribute(Attribute::float(
            "sharpness",
            (0..n).map(|i| (i % 97) as f64 / 97.0).collect::<Vec<f64>>(),
        ))
        .expect("sharpness");
    cloud
        .set_attribute(Attribute::int(
            "surface",
            (0..n).map(|i| (i % 300) as i64 - 1),
        ))
        .expect("surface");
    for name in ["surface_type", "fillet_label"] {
        let mut a = Attribute::int(name, (0..n).map(|i| (i % 5) as i64));
        a.kind = crease::geometry::ScalarKind::U8;
        cloud.set_attribute(a).expect("labels");
    }
    cloud
        .set_attribute(Attribute::flag("smooth_edge", (0..n).map(|i| i % 17 == 0)))
        .expect("smooth_edge");
    let scene = Scene {
        points: Some(&cloud),
        mesh: None,
        polylines: Vec::new(),
    };
    let html = page(&scene, &PageParams::default()).expect("page");
    assert!(
        html.len() < 40_000_000,
        "{} bytes for 1M points",
        html.len()
    );
    assert!(html.contains("\"points\":1000000,") && html.contains("\"total_points\":1000000"));
    assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));
    let small = page(
        &scene,
        &PageParams {
            max_points: 250_000,
            ..Default::default()
        },
    )
    .expect("page");
    assert!(
        small.contains("\"points\":250000,"),
        "an even subsample of 250,000"
    );
    assert!(small.len() * 3 < html.len());
    let empty = Scene::default();
    assert!(page(&empty, &PageParams::default()).is_err());
}
