//! `crease train MESH[=TRUTH]... -o MODEL.json`: trains the learned edge classifier of
//! `crease edges --method learned|potts-learned` (vidal et al. 2011, section 6.3: RBF SVM on
//! the 43 features of section 4, class weight 9, grid search with cross-validation maximising
//! the AUC) on meshes with ground truth, each in clean and noisy versions (section 6.1).

use std::collections::HashSet;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use crease::meshfeat::svm::train;
use crease::meshfeat::{
    dihedral_labels, labels_from_pairs, read_abc_sharp_edges, training_set, EdgeMesh,
    FeatureParams, LabelledMesh, SetParams, TrainParams,
};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease train`.
#[derive(Args, Debug)]
pub struct TrainArgs {
    /// Meshes with ground truth. `MESH`: its own edge property `gt_sharp` or `sharp` (a PLY
    /// `edge` element) if it has one, else the section 6.1 protocol: the clean mesh's edges
    /// with a dihedral angle above --label-degrees. `MESH=TRUTH`: TRUTH is an ABC features
    /// .yml (its `sharp` curves) or a file with the same vertices and an edge property
    /// `gt_sharp` or `sharp`.
    pub meshes: Vec<String>,
    /// The model file to write (JSON).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also train on crease's synthetic parts (the data of the shipped default model).
    #[arg(long)]
    pub synthetic: bool,
    /// Dihedral angle above which an edge of a clean mesh without labels is a feature edge.
    #[arg(long, default_value_t = 25.0)]
    pub label_degrees: f64,
    /// Versions of every mesh: Gaussian noise of these fractions of the bounding box's largest
    /// side (0 = the mesh as given; section 6.1 uses 0.005).
    #[arg(long, value_delimiter = ',', default_values_t = vec![0.0, 0.005])]
    pub noise: Vec<f64>,
    /// At most this many edges of every mesh version (class proportions kept).
    #[arg(long, default_value_t = 400)]
    pub max_edges: usize,
    /// Cross-validation folds of the grid search (0 = no search: the first C and gamma).
    #[arg(long, default_value_t = 3)]
    pub folds: usize,
    /// Candidate C of the grid search (comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub c: Vec<f64>,
    /// Candidate RBF gamma of the grid search (comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub gamma: Vec<f64>,
}

fn labelled(g: &Global, spec: &str, label_degrees: f64) -> anyhow::Result<LabelledMesh> {
    let (mesh_path, truth_path) = match spec.split_once('=') {
        Some((m, t)) => (PathBuf::from(m), Some(PathBuf::from(t))),
        None => (PathBuf::from(spec), None),
    };
    let (geom, _) = super::load(g, &mesh_path)?;
    let own_pairs = edge_property_pairs(&geom);
    let Some(mesh) = geom.into_mesh() else {
        anyhow::bail!(
            "{}: no faces; training needs triangle meshes",
            mesh_path.display()
        );
    };
    let em = EdgeMesh::new(&mesh).map_err(|e| anyhow::anyhow!("{}: {e}", mesh_path.display()))?;
    let (truth, source) = match &truth_path {
        Some(t) => {
            let is_yml = t
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("yml") || e.eq_ignore_ascii_case("yaml"));
            let pairs = if is_yml {
                read_abc_sharp_edges(t)?
            } else {
                let (tg, _) = super::load(g, t)?;
                if tg.points.len() != mesh.vertices.len() {
                    anyhow::bail!(
                        "{}: {} vertices, but {} has {}",
                        t.display(),
                        tg.points.len(),
                        mesh_path.display(),
                        mesh.vertices.len()
                    );
                }
                edge_property_pairs(&tg).ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}: no edge property gt_sharp or sharp holding the true feature edges",
                        t.display()
                    )
                })?
            };
            let n = mesh.vertices.len();
            if let Some(e) = pairs
                .iter()
                .find(|e| e[0] as usize >= n || e[1] as usize >= n)
            {
                anyhow::bail!(
                    "{}: true edge ({}, {}) refers to a vertex beyond the {n} of {}",
                    t.display(),
                    e[0],
                    e[1],
                    mesh_path.display()
                );
            }
            let (truth, missing) = labels_from_pairs(&em.topo, &pairs);
            if missing > 0 {
                tracing::warn!(
                    "{}: {missing} true edges are not edges of {}",
                    t.display(),
                    mesh_path.display()
                );
            }
            (truth, t.display().to_string())
        }
        None => match own_pairs {
            Some(pairs) => (
                labels_from_pairs(&em.topo, &pairs).0,
                "edge property".into(),
            ),
            None => (
                dihedral_labels(&em, label_degrees),
                format!("dihedral > {label_degrees} deg"),
            ),
        },
    };
    drop(em);
    tracing::info!("{}: labels from {source}", mesh_path.display());
    Ok(LabelledMesh {
        name: mesh_path.display().to_string(),
        mesh,
        truth,
    })
}

/// The vertex pairs of the edges whose `gt_sharp` (else `sharp`) property is non-zero.
fn edge_property_pairs(geom: &crease::io::Geometry) -> Option<Vec<[u32; 2]>> {
    let attr = ["gt_sharp", "sharp"]
        .iter()
        .find_map(|n| geom.edge_attributes.get(n))?;
    let set: HashSet<[u32; 2]> = geom
        .edges
        .iter()
        .zip(&attr.values)
        .filter(|(_, &v)| v > 0.0)
        .map(|(&e, _)| e)
        .collect();
    let mut v: Vec<[u32; 2]> = set.into_iter().collect();
    v.sort_unstable();
    Some(v)
}

pub fn run(g: &Global, a: &TrainArgs) -> anyhow::Result<()> {
    if a.meshes.is_empty() && !a.synthetic {
        return Err(usage("give meshes with ground truth and/or --synthetic"));
    }
    let ext = a.output.extension().and_then(|e| e.to_str());
    if !ext.is_some_and(|e| e.eq_ignore_ascii_case("json")) {
        return Err(usage(format!(
            "the model is written as JSON; name it *.json, not {}",
            a.output.display()
        )));
    }
    if !(a.label_degrees.is_finite() && a.label_degrees > 0.0 && a.label_degrees < 180.0) {
        return Err(usage(format!(
            "--label-degrees must be in (0, 180), got {}",
            a.label_degrees
        )));
    }
    if let Some(n) = a.noise.iter().find(|n| !(n.is_finite() && **n >= 0.0)) {
        return Err(usage(format!("--noise must be finite and >= 0, got {n}")));
    }
    if a.max_edges < 2 {
        return Err(usage("--max-edges must be at least 2"));
    }
    if let Some(v) =
        a.c.iter()
            .chain(&a.gamma)
            .find(|v| !(v.is_finite() && **v > 0.0))
    {
        return Err(usage(format!("--c and --gamma must be positive, got {v}")));
    }
    let inputs: Vec<PathBuf> = a
        .meshes
        .iter()
        .flat_map(|s| s.split('=').map(PathBuf::from).collect::<Vec<_>>())
        .collect();
    let refs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    crate::ui::ensure_not_input(&a.output, &refs)?;
    let start = Instant::now();
    let mut meshes = Vec::new();
    for spec in &a.meshes {
        meshes.push(labelled(g, spec, a.label_degrees)?);
    }
    if a.synthetic {
        for (name, m) in crease::synth::training_meshes(&[40.0, 70.0])? {
            meshes.push(LabelledMesh::from_pairs(name, m.mesh, &m.sharp_edges)?);
        }
    }
    let fp = FeatureParams::default();
    let sp = SetParams {
        noise: if a.noise.is_empty() {
            vec![0.0]
        } else {
            a.noise.clone()
        },
        max_edges_per_mesh: a.max_edges,
        ..SetParams::default()
    };
    let stage = Stage::start("edge features", g.quiet);
    let set = training_set(&meshes, &fp, &sp)?;
    stage.finish();
    let d = TrainParams::default();
    let tp = TrainParams {
        c_grid: if a.c.is_empty() {
            d.c_grid
        } else {
            a.c.clone()
        },
        gamma_grid: if a.gamma.is_empty() {
            d.gamma_grid
        } else {
            a.gamma.clone()
        },
        folds: a.folds,
        description: format!(
            "crease train: {} meshes{}, noise {:?}, <= {} edges per mesh version",
            a.meshes.len(),
            if a.synthetic {
                " + synthetic parts"
            } else {
                ""
            },
            sp.noise,
            a.max_edges
        ),
        ..d
    };
    let stage = Stage::start("SVM grid search", g.quiet);
    let (model, grid) = train(&set, &fp, &tp)?;
    stage.finish();
    model.write(&a.output)?;
    let npos = set.y.iter().filter(|&&t| t).count();
    if g.json {
        let cells: Vec<serde_json::Value> = grid
            .iter()
            .map(|(c, gm, auc)| serde_json::json!({"c": c, "gamma": gm, "cv_auc": auc}))
            .collect();
        crate::ui::print_json(&serde_json::json!({
            "output": a.output, "meshes": meshes.len(),
            "training_edges": set.len(), "feature_edges": npos,
            "c": model.c, "gamma": model.gamma, "cv_auc": model.cv_auc,
            "support_vectors": model.num_support(), "grid": cells,
            "seconds": start.elapsed().as_secs_f64(),
        }))?;
    } else if !g.quiet {
        eprintln!(
            "wrote {}: {} support vectors, C {} gamma {}, cross-validation AUC {:.2} % \
             ({} training edges, {npos} feature), {:.1} s",
            a.output.display(),
            model.num_support(),
            model.c,
            model.gamma,
            100.0 * model.cv_auc,
            set.len(),
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
