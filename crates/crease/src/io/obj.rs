//! obj reading and writing (to be written).

use std::path::Path;

use super::{Geometry, ReadReport, WriteOptions};
use crate::{Error, Result};

/// Reads a obj file.
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    Err(Error::Unsupported {
        path: path.to_path_buf(),
        message: "not yet".into(),
    })
}

/// Writes a obj file.
pub fn write(path: &Path, _geom: &Geometry, _opts: &WriteOptions) -> Result<()> {
    Err(Error::Unsupported {
        path: path.to_path_buf(),
        message: "not yet".into(),
    })
}
