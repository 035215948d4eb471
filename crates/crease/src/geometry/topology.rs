//! Mesh edge topology (to be written).

/// Edge topology of a triangle mesh.
#[derive(Debug, Clone, Default)]
pub struct MeshTopology {}
