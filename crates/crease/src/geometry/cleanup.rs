//! Mesh clean-up (to be written).
use super::TriMesh;

/// Clean-up parameters.
#[derive(Debug, Clone, Default)]
pub struct CleanupParams {}
/// What the clean-up did.
#[derive(Debug, Clone, Default)]
pub struct CleanupReport {}
/// Cleans a mesh.
pub fn clean_mesh(mesh: &TriMesh, _p: &CleanupParams) -> (TriMesh, CleanupReport) {
    (mesh.clone(), CleanupReport {})
}
