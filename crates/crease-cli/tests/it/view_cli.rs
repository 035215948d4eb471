//! `crease view` and `crease run`'s report.html, rendered by a real browser: Chromium headless
//! with WebGL on SwiftShader (Debian's `chromium`, installed by `.ci/run`). Screenshots are
//! checked on their pixels (geometry drawn, the sharp lines' colour present, a layer toggled off
//! removes it, the B-rep's faces drawn when their layer is on, another colouring changes the
//! picture), a click shows the surface under it, and
//! the browser's network log shows no request from the page. Without Chromium the tests skip,
//! except under `CI=true`, where they fail.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::{crease, synth};

/// The window the pages are drawn in.
const SIZE: (u32, u32) = (1000, 700);
/// The page's background (view.css).
const BACKGROUND: [u8; 3] = [0x16, 0x16, 0x1d];
/// The sharp lines' colour in `crease run`'s report.
const SHARP: [u8; 3] = [220, 30, 30];

/// Chromium: $CREASE_CHROMIUM, Debian's binary, or `chromium` on the PATH.
fn chromium() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("CREASE_CHROMIUM").map(PathBuf::from),
        Some(PathBuf::from("/usr/lib/chromium/chromium")),
        Some(PathBuf::from("/usr/bin/chromium")),
    ];
    if let Some(p) = candidates.into_iter().flatten().find(|p| p.is_file()) {
        return Some(p);
    }
    assert!(
        std::env::var("CI").map(|v| v != "true").unwrap_or(true),
        "CI=true but Chromium is missing (.ci/run installs Debian's chromium)"
    );
    eprintln!("skipping: Chromium not found");
    None
}

/// Chromium with WebGL on the CPU and every network path closed (a proxy that does not exist,
/// no name resolution), so that nothing leaves the machine whatever the page asks for.
fn browser(exe: &Path) -> Command {
    let mut c = Command::new(exe);
    c.args([
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-extensions",
        "--proxy-server=127.0.0.1:9",
        "--proxy-bypass-list=<-loopback>",
        "--host-resolver-rules=MAP * ~NOTFOUND",
        "--hide-scrollbars",
        "--virtual-time-budget=10000",
    ])
    .arg(format!("--window-size={},{}", SIZE.0, SIZE.1))
    .arg(format!(
        "--user-data-dir={}",
        tempfile::tempdir().expect("tmp").keep().display()
    ));
    c
}

fn url(page: &Path, fragment: &str) -> String {
    let abs = std::fs::canonicalize(page).expect("page exists");
    format!("file://{}{fragment}", abs.display())
}

/// The page drawn into a PNG, as RGB pixels.
fn screenshot(exe: &Path, page: &Path, fragment: &str) -> Vec<[u8; 3]> {
    let png = tempfile::Builder::new()
        .suffix(".png")
        .tempfile()
        .expect("tmp");
    let out = browser(exe)
        .arg(format!("--screenshot={}", png.path().display()))
        .arg(url(page, fragment))
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "chromium failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = tiny_skia::Pixmap::load_png(png.path()).expect("a PNG screenshot");
    assert_eq!((img.width(), img.height()), SIZE);
    img.pixels()
        .iter()
        .map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue()]
        })
        .collect()
}

/// The page's DOM once drawn (and clicked, with `#click=X,Y`).
fn dom(exe: &Path, page: &Path, fragment: &str, extra: &[String]) -> String {
    let out = browser(exe)
        .args(extra)
        .arg("--dump-dom")
        .arg(url(page, fragment))
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "chromium failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Pixels of the picture for which `f` holds, the panel's corner (top left, with its colour
/// swatches) left out.
fn count(pixels: &[[u8; 3]], f: impl Fn([u8; 3]) -> bool) -> usize {
    pixels
        .iter()
        .enumerate()
        .filter(|&(i, &p)| {
            let (x, y) = (i as u32 % SIZE.0, i as u32 / SIZE.0);
            !(x < 330 && y < 400) && f(p)
        })
        .count()
}

fn near(a: [u8; 3], b: [u8; 3], tol: i32) -> bool {
    (0..3).all(|k| (i32::from(a[k]) - i32::from(b[k])).abs() <= tol)
}

/// The text of `<div id="info">` in a DOM dump.
fn info(dom: &str) -> &str {
    let start = dom.find("<div id=\"info\"").expect("the info panel");
    let text = &dom[start..];
    let open = text.find('>').expect("tag") + 1;
    let close = text.find("</div>").expect("closing tag");
    &text[open..close]
}

/// `crease run` on a synthetic part with sharp edges, a fillet and a cone: its report.html.
fn report(dir: &Path) -> PathBuf {
    let part = synth(
        dir,
        &["synth", "fillet-chamfer-cone", "-n", "30000"],
        "part.ply",
    );
    let out = dir.join("run");
    crease()
        .args(["run", "-q", "--no-picture"])
        .arg(&part)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    out.join("report.html")
}

#[test]
fn the_report_draws_points_and_lines_and_its_layers_toggle() {
    let Some(exe) = chromium() else { return };
    let dir = tempfile::tempdir().expect("tmp");
    let page = report(dir.path());
    let html = std::fs::read_to_string(&page).expect("report.html");
    assert!(html.contains("Content-Security-Policy") && html.contains("default-src 'none'"));
    assert!(
        html.contains("Copyright © 2010-2024 three.js authors"),
        "three.js' licence kept"
    );

    let shown = screenshot(&exe, &page, "");
    let drawn = count(&shown, |p| !near(p, BACKGROUND, 6));
    let red = count(&shown, |p| near(p, SHARP, 3));
    assert!(drawn > 60_000, "{drawn} pixels drawn");
    assert!(red > 400, "{red} pixels of the sharp lines' colour");

    let no_sharp = screenshot(&exe, &page, "#layer-sharp+line=off");
    let red_off = count(&no_sharp, |p| near(p, SHARP, 3));
    assert!(
        red_off * 50 < red,
        "sharp layer off: {red_off} red pixels left of {red}"
    );

    let no_points = screenshot(&exe, &page, "#points=off");
    let drawn_lines = count(&no_points, |p| !near(p, BACKGROUND, 6));
    assert!(
        drawn_lines * 5 < drawn,
        "points off: {drawn_lines} of {drawn} pixels left"
    );

    // The B-rep's faces, a layer off when the page opens, drawn when switched on.
    let brep = screenshot(&exe, &page, "#points=off&layer-B-rep=on");
    let drawn_brep = count(&brep, |p| !near(p, BACKGROUND, 6));
    assert!(
        drawn_brep > 5 * drawn_lines && drawn_brep > 60_000,
        "B-rep layer on: {drawn_brep} pixels, lines alone {drawn_lines}"
    );

    let by_sharpness = screenshot(&exe, &page, "#color=sharpness");
    let changed = shown
        .iter()
        .zip(&by_sharpness)
        .filter(|(a, b)| !near(**a, **b, 10))
        .count();
    assert!(
        changed > 20_000,
        "colouring by sharpness changed {changed} pixels"
    );
}

#[test]
fn a_click_shows_the_surface_under_it() {
    let Some(exe) = chromium() else { return };
    let dir = tempfile::tempdir().expect("tmp");
    let page = report(dir.path());
    // The middle of the window is on the part's top (a plane).
    let d = dom(
        &exe,
        &page,
        &format!("#click={},{}", SIZE.0 / 2, SIZE.1 / 2 + 60),
        &[],
    );
    assert!(d.contains("data-ready=\"1\""), "the page finished drawing");
    let text = info(&d);
    assert!(text.starts_with("point "), "{text}");
    assert!(text.contains("surface_type: plane"), "{text}");
    assert!(
        text.contains(": plane\nnormal: ["),
        "the surface's parameters: {text}"
    );
    assert!(text.contains("RMS: "), "{text}");

    // Above --max-points, an even subsample, said on the page.
    let labels = page.with_file_name("labels.ply");
    let small = page.with_file_name("small.html");
    crease()
        .args(["view", "-q", "--max-points", "5000"])
        .arg(&labels)
        .arg("-o")
        .arg(&small)
        .assert()
        .success();
    let d = dom(&exe, &small, "", &[]);
    assert!(
        d.contains("showing 5,000 of 30,000 points (an even subsample)"),
        "the note on the page"
    );
}

#[test]
fn a_mesh_view_draws_its_faces_and_a_click_names_the_face() {
    let Some(exe) = chromium() else { return };
    let dir = tempfile::tempdir().expect("tmp");
    let mesh = synth(
        dir.path(),
        &["synth", "cube", "--mesh", "-n", "3000"],
        "cube.ply",
    );
    let seg = dir.path().join("seg.ply");
    let prims = dir.path().join("seg.json");
    crease()
        .args(["segment", "-q"])
        .arg(&mesh)
        .arg("-o")
        .arg(&seg)
        .arg("--primitives")
        .arg(&prims)
        .assert()
        .success();
    let page = dir.path().join("view.html");
    crease()
        .args(["view", "-q"])
        .arg(&mesh)
        .arg("--surfaces")
        .arg(&seg)
        .arg("--primitives")
        .arg(&prims)
        .arg("-o")
        .arg(&page)
        .assert()
        .success();
    let shown = screenshot(&exe, &page, "");
    let drawn = count(&shown, |p| !near(p, BACKGROUND, 6));
    assert!(drawn > 100_000, "{drawn} pixels of faces");
    let text_dom = dom(
        &exe,
        &page,
        &format!("#click={},{}", SIZE.0 / 2, SIZE.1 / 2),
        &[],
    );
    let text = info(&text_dom);
    assert!(text.starts_with("face "), "{text}");
    assert!(
        text.contains("surface_type: plane") && text.contains(": plane\n"),
        "{text}"
    );
}

#[test]
fn the_page_makes_no_network_request() {
    let Some(exe) = chromium() else { return };
    let dir = tempfile::tempdir().expect("tmp");
    let page = report(dir.path());
    // Chromium's network log: the page's own requests carry its file:// isolation key (the
    // browser's background requests do not).
    let requests = |page: &Path| {
        let log = dir.path().join("net.json");
        let _ = std::fs::remove_file(&log);
        dom(
            &exe,
            page,
            "",
            &[format!("--log-net-log={}", log.display())],
        );
        let text = std::fs::read_to_string(&log).expect("a network log");
        text.matches("network_isolation_key\":\"file://").count()
    };
    assert_eq!(requests(&page), 0, "report.html made a request");
    // The check sees a page that does make one.
    let control = dir.path().join("control.html");
    std::fs::write(
        &control,
        "<!DOCTYPE html><html><body><img src=\"http://127.0.0.1:9/x.png\"></body></html>",
    )
    .expect("write");
    assert!(requests(&control) > 0, "the network log missed a request");
}

#[test]
fn view_refuses_what_it_cannot_show() {
    let dir = tempfile::tempdir().expect("tmp");
    let part = synth(dir.path(), &["synth", "cube", "-n", "2000"], "cube.ply");
    crease()
        .arg("view")
        .arg(&part)
        .arg("-o")
        .arg(dir.path().join("view.png"))
        .assert()
        .code(2)
        .stderr(predicates::str::contains("HTML"));
    let other = synth(dir.path(), &["synth", "cube", "-n", "1000"], "other.ply");
    crease()
        .arg("view")
        .arg(&part)
        .arg("--surfaces")
        .arg(&other)
        .arg("-o")
        .arg(dir.path().join("v.html"))
        .assert()
        .code(2)
        .stderr(predicates::str::contains("other.ply"));
    assert!(!dir.path().join("v.html").exists());
}
