//! `crease eval PRED --gt GT [--label sharp] [--score sharpness] [--gt-label NAME | --gt-colors]
//! [--tolerance D] [--roc OUT.csv]`: scores a labelled output against ground truth, point by
//! point: precision, recall, F1, MCC, IoU of the sharp class, the same within a distance
//! tolerance, and the ROC curve and AUC of a continuous score. The measures live in
//! `crease::eval`.

use std::path::{Path, PathBuf};

use clap::Args;
use crease::eval::{
    check_same_points, evaluate, labels_from_property, read_truth, scores_from_property,
    EvalParams, EvalReport, Labels, TruthSource,
};

use crate::args::Global;
use crate::ui::usage;

/// The score property used when present, unless `--score` names another.
const DEFAULT_SCORE: &str = "sharpness";

/// Arguments of `crease eval`.
#[derive(Args, Debug)]
#[command(
    after_help = "PRED and GT must list the same points in the same order (they may be \
the same file, e.g. a synthetic part carrying both gt_sharp and a detector's sharp). \
Ground truth, unless --gt-label or --gt-colors is given: the first of the properties gt_sharp, \
sharp, label, class present in GT (> 0 = sharp), else the PCEDNet colour classes \
(white flat, red sharp, black / orange / gold smooth edge). Smooth-edge points count as not sharp."
)]
pub struct EvalArgs {
    /// The labelled output to score (e.g. written by `crease sharp`).
    pub pred: PathBuf,
    /// The ground truth: a file with the same points in the same order.
    #[arg(long, value_name = "GT")]
    pub gt: PathBuf,
    /// Property of PRED holding the predicted labels (> 0 = sharp).
    #[arg(long, default_value = "sharp", value_name = "NAME")]
    pub label: String,
    /// Property of PRED holding a continuous score (larger = sharper) for the ROC curve
    /// [default: sharpness, when present].
    #[arg(long, value_name = "NAME")]
    pub score: Option<String>,
    /// Property of GT holding the true labels (> 0 = sharp).
    #[arg(long, value_name = "NAME", conflicts_with = "gt_colors")]
    pub gt_label: Option<String>,
    /// Read the true classes from GT's colours (PCEDNet benchmark).
    #[arg(long)]
    pub gt_colors: bool,
    /// Distance of the tolerant scores [default: 2 x the average spacing of GT].
    #[arg(long, value_name = "D")]
    pub tolerance: Option<f64>,
    /// Write the full ROC curve as CSV (threshold,fpr,tpr; one row per distinct score).
    #[arg(long, value_name = "OUT.csv")]
    pub roc: Option<PathBuf>,
    /// Score mesh edges instead of points: the labels and score are properties of PRED's
    /// `edge` element (as `crease edges` writes); GT is an ABC features .yml (its `sharp`
    /// curves' edges) or a file with an `edge` element whose --gt-label property (default
    /// gt_sharp or sharp) marks the true feature edges. Edges are matched by vertex pair.
    #[arg(long, conflicts_with = "gt_colors")]
    pub edges: bool,
}

pub fn run(g: &Global, a: &EvalArgs) -> anyhow::Result<()> {
    if a.edges {
        return run_edges(g, a);
    }
    if let Some(t) = a.tolerance {
        if !(t.is_finite() && t >= 0.0) {
            return Err(usage(format!(
                "--tolerance must be a finite distance >= 0, got {t}"
            )));
        }
    }
    if let Some(roc) = &a.roc {
        crate::ui::ensure_not_input(roc, &[&a.pred, &a.gt])?;
    }
    let (gt_geom, _) = super::load(g, &a.gt)?;
    let same_file = same_path(&a.pred, &a.gt);
    let pred_geom = if same_file {
        None
    } else {
        Some(super::load(g, &a.pred)?.0)
    };
    let gt = &gt_geom.points;
    let pred = pred_geom.as_ref().map_or(gt, |p| &p.points);
    check_same_points(&pred.positions, &a.pred, &gt.positions, &a.gt)?;

    let source = match (&a.gt_label, a.gt_colors) {
        (Some(name), _) => TruthSource::Property(name.clone()),
        (None, true) => TruthSource::Colors,
        (None, false) => TruthSource::Auto,
    };
    let truth = read_truth(gt, &source, &a.gt)?;
    let predicted = labels_from_property(pred, &a.label, &a.pred, "predicted labels")?;
    let score_name = match &a.score {
        Some(s) => Some(s.as_str()),
        None => pred.attribute(DEFAULT_SCORE).map(|_| DEFAULT_SCORE),
    };
    let scores = score_name
        .map(|s| scores_from_property(pred, s, &a.pred))
        .transpose()?;

    let report = evaluate(
        &Labels {
            predicted: &predicted,
            truth: &truth.sharp,
            scores: scores.as_deref(),
            positions: Some(&gt.positions),
            classes: truth.classes.as_deref(),
        },
        &EvalParams {
            tolerance: a.tolerance,
            ..Default::default()
        },
    )
    .map_err(|e| anyhow::anyhow!("{} vs {}: {e}", a.pred.display(), a.gt.display()))?;

    if let Some(path) = &a.roc {
        let Some(roc) = &report.roc else {
            let why = if score_name.is_none() {
                format!(
                    "{} has no score property (looked for {DEFAULT_SCORE:?}; name one with --score)",
                    a.pred.display()
                )
            } else {
                report.notes.join("; ")
            };
            return Err(anyhow::anyhow!(
                "cannot write the ROC curve {}: {why}",
                path.display()
            ));
        };
        write_roc(path, &roc.full)?;
    }

    if g.json {
        let mut v = serde_json::to_value(&report)?;
        v["prediction"] = serde_json::json!({
            "file": a.pred, "label": a.label, "score": score_name,
        });
        v["ground_truth"] = serde_json::json!({
            "file": a.gt, "source": truth.source,
        });
        v["roc_csv"] = serde_json::json!(a.roc);
        crate::ui::print_json(&v)?;
    } else {
        crate::ui::out(&text_report(
            a,
            &truth.source,
            &a.label,
            score_name,
            &report,
        ))?;
    }
    Ok(())
}

/// `crease eval --edges`: per-edge scores (see [`EvalArgs::edges`]).
fn run_edges(g: &Global, a: &EvalArgs) -> anyhow::Result<()> {
    use std::collections::HashSet;
    if let Some(roc) = &a.roc {
        crate::ui::ensure_not_input(roc, &[&a.pred, &a.gt])?;
    }
    let (pred, _) = super::load(g, &a.pred)?;
    if pred.edges.is_empty() {
        anyhow::bail!(
            "{}: no edge element; --edges scores the edges written by `crease edges`",
            a.pred.display()
        );
    }
    let ext =
        a.gt.extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
    let (true_pairs, source) = if matches!(ext.as_deref(), Some("yml" | "yaml")) {
        let pairs = crease::meshfeat::read_abc_sharp_edges(&a.gt)?;
        (pairs, "ABC sharp curves".to_string())
    } else {
        let (gt, _) = super::load(g, &a.gt)?;
        if !same_path(&a.pred, &a.gt) {
            check_same_points(&pred.points.positions, &a.pred, &gt.points.positions, &a.gt)?;
        }
        let names: Vec<String> = match &a.gt_label {
            Some(n) => vec![n.clone()],
            None => vec!["gt_sharp".into(), "sharp".into()],
        };
        let Some(attr) = names.iter().find_map(|n| gt.edge_attributes.get(n)) else {
            anyhow::bail!(
                "{}: no edge property {} holding the true feature edges",
                a.gt.display(),
                names.join(" or ")
            );
        };
        let pairs = gt
            .edges
            .iter()
            .zip(&attr.values)
            .filter(|(_, &v)| v > 0.0)
            .map(|(&e, _)| e)
            .collect();
        (pairs, format!("edge property {}", attr.name))
    };
    let key = |e: [u32; 2]| (e[0].min(e[1]), e[0].max(e[1]));
    let set: HashSet<(u32, u32)> = true_pairs.iter().map(|&e| key(e)).collect();
    let truth: Vec<bool> = pred.edges.iter().map(|&e| set.contains(&key(e))).collect();
    let found = truth.iter().filter(|&&t| t).count();
    let n_pts = pred.points.len();
    if let Some(e) = true_pairs
        .iter()
        .find(|e| e[0] as usize >= n_pts || e[1] as usize >= n_pts)
    {
        anyhow::bail!(
            "{}: true edge ({}, {}) refers to a vertex beyond the {n_pts} of {}",
            a.gt.display(),
            e[0],
            e[1],
            a.pred.display()
        );
    }
    let label_attr = pred
        .edge_attributes
        .get(&a.label)
        .ok_or_else(|| anyhow::anyhow!("{}: no edge property {:?}", a.pred.display(), a.label))?;
    let predicted: Vec<bool> = label_attr.values.iter().map(|&v| v > 0.0).collect();
    let score_name = match &a.score {
        Some(s) => Some(s.as_str()),
        None => pred
            .edge_attributes
            .get(DEFAULT_SCORE)
            .map(|_| DEFAULT_SCORE),
    };
    let scores = match score_name {
        Some(n) => Some(
            pred.edge_attributes
                .get(n)
                .ok_or_else(|| anyhow::anyhow!("{}: no edge property {n:?}", a.pred.display()))?
                .values
                .clone(),
        ),
        None => None,
    };
    let p = &pred.points.positions;
    let mids: Vec<[f64; 3]> = pred
        .edges
        .iter()
        .map(|&[u, v]| {
            let (x, y) = (p[u as usize], p[v as usize]);
            [0, 1, 2].map(|k| 0.5 * (x[k] + y[k]))
        })
        .collect();
    let report = evaluate(
        &Labels {
            predicted: &predicted,
            truth: &truth,
            scores: scores.as_deref(),
            positions: Some(&mids),
            classes: None,
        },
        &EvalParams {
            tolerance: a.tolerance,
            ..Default::default()
        },
    )
    .map_err(|e| anyhow::anyhow!("{} vs {}: {e}", a.pred.display(), a.gt.display()))?;
    if let (Some(path), Some(roc)) = (&a.roc, &report.roc) {
        write_roc(path, &roc.full)?;
    }
    let missing = set.len() - found;
    if g.json {
        let mut v = serde_json::to_value(&report)?;
        v["prediction"] = serde_json::json!({
            "file": a.pred, "label": a.label, "score": score_name, "items": "edges",
        });
        v["ground_truth"] = serde_json::json!({
            "file": a.gt, "source": source, "true_edges_not_in_prediction": missing,
        });
        v["roc_csv"] = serde_json::json!(a.roc);
        crate::ui::print_json(&v)?;
    } else {
        crate::ui::out(&text_report(a, &source, &a.label, score_name, &report))?;
        if missing > 0 {
            crate::ui::outln(format_args!(
                "note: {missing} true edges are not edges of the prediction"
            ))?;
        }
    }
    Ok(())
}

fn same_path(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

fn write_roc(path: &Path, roc: &crease::eval::Roc) -> anyhow::Result<()> {
    let mut text = String::from("threshold,fpr,tpr\n");
    for p in &roc.points {
        text += &format!("{},{},{}\n", p.threshold, p.fpr, p.tpr);
    }
    crate::ui::write_text(path, &text)
}

/// The text report: the inputs, then an aligned table of the exact and tolerant scores.
fn text_report(
    a: &EvalArgs,
    truth_source: &str,
    label: &str,
    score: Option<&str>,
    r: &EvalReport,
) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let c = &r.confusion;
    let _ = writeln!(
        s,
        "prediction    {} (label {label}{})",
        a.pred.display(),
        score.map_or(String::new(), |n| format!(", score {n}"))
    );
    let _ = writeln!(s, "ground truth  {} ({truth_source})", a.gt.display());
    let _ = writeln!(
        s,
        "points        {}: {} sharp, {} not sharp; {} predicted sharp",
        r.items,
        c.positives(),
        c.negatives(),
        c.predicted_positives()
    );
    let _ = writeln!(
        s,
        "confusion     tp {}  fp {}  tn {}  fn {}",
        c.tp, c.fp, c.tn, c.fn_
    );
    let _ = writeln!(s);
    let m = &r.metrics;
    let t = r.tolerant.as_ref();
    let head = t.map_or(String::new(), |t| format!("within {}", short(t.tolerance)));
    let w = head.len().max(8);
    let _ = writeln!(s, "{:<13}{:>8}  {head:>w$}", "", "exact");
    let row = |s: &mut String, name: &str, exact: f64, tol: Option<f64>| {
        let tol = tol.map_or(String::new(), |v| format!("  {v:>w$.4}"));
        let _ = writeln!(s, "{name:<13}{exact:>8.4}{tol}");
    };
    row(&mut s, "precision", m.precision, t.map(|t| t.precision));
    row(&mut s, "recall", m.recall, t.map(|t| t.recall));
    row(&mut s, "F1", m.f1, t.map(|t| t.f1));
    row(&mut s, "MCC", m.mcc, None);
    row(&mut s, "IoU", m.iou, None);
    row(&mut s, "accuracy", m.accuracy, None);
    row(&mut s, "specificity", m.specificity, None);
    if let Some(roc) = &r.roc {
        let _ = writeln!(
            s,
            "{:<13}{:>8.4}  ({} thresholds)",
            "AUC",
            roc.auc,
            roc.full_points - 1
        );
    }
    if let Some(rows) = &r.classes {
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "{:<13}{:>8}  {:>15}",
            "true class", "points", "predicted sharp"
        );
        for row in rows {
            let _ = writeln!(
                s,
                "{:<13}{:>8}  {:>15}",
                row.class.name(),
                row.count,
                row.predicted_positive
            );
        }
    }
    for n in &r.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}

/// A distance with 4 significant digits.
fn short(d: f64) -> String {
    format!("{d:.4e}")
        .parse::<f64>()
        .map_or_else(|_| d.to_string(), |v| v.to_string())
}
