//! Conversions between numpy arrays / Python objects and the library's types, and the mapping
//! of the library's errors to Python exceptions.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crease::geometry::{Attribute, Attributes, ScalarKind};

/// A ValueError with `msg`.
pub fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// The Python exception for a library error: `OSError` (with its errno, so that Python picks
/// `FileNotFoundError`, `PermissionError`, ...) when the operating system refused a file,
/// `crease.FileFormatError` (both an `OSError` and a `ValueError`) when a file's content is
/// wrong or its extension unknown, `ValueError` for unusable input or arguments. The message is
/// the library's, as the CLI prints it after `error: `.
pub fn to_py_err(py: Python<'_>, e: crease::Error) -> PyErr {
    let msg = e.to_string();
    match e {
        crease::Error::Io { error, .. } => match error.raw_os_error() {
            Some(code) => os_error(py, code, msg),
            None => PyOSError::new_err(msg),
        },
        crease::Error::Format { .. }
        | crease::Error::UnknownFormat { .. }
        | crease::Error::Unsupported { .. } => format_error(py, msg),
        crease::Error::InvalidInput(_) | crease::Error::InvalidArgument(_) => value_error(msg),
    }
}

/// `OSError` of the subclass Python picks for the errno `code` (`FileNotFoundError`, ...) with
/// the CLI's message as its text (see `crease/_errors.py`).
fn os_error(py: Python<'_>, code: i32, msg: String) -> PyErr {
    match py
        .import("crease._errors")
        .and_then(|m| m.getattr("os_error"))
        .and_then(|f| f.call1((code, msg.clone())))
    {
        Ok(obj) => PyErr::from_value(obj),
        Err(_) => PyOSError::new_err((code, msg)),
    }
}

/// `crease.CommandError(code, msg)`: a command line run by `crease.command` failed (see
/// `crease/_errors.py`); a `RuntimeError` if that module cannot be imported.
pub fn command_error(py: Python<'_>, code: u8, msg: String) -> PyErr {
    match py
        .import("crease._errors")
        .and_then(|m| m.getattr("CommandError"))
        .and_then(|c| c.call1((code, msg.clone())))
    {
        Ok(obj) => PyErr::from_value(obj),
        Err(_) => PyRuntimeError::new_err(msg),
    }
}

/// `crease.FileFormatError(msg)`, defined in Python (it derives from both `OSError` and
/// `ValueError`, which a native exception type cannot); a plain `ValueError` if that module
/// cannot be imported.
fn format_error(py: Python<'_>, msg: String) -> PyErr {
    match py
        .import("crease._errors")
        .and_then(|m| m.getattr("FileFormatError"))
    {
        Ok(cls) => match cls.call1((msg.clone(),)) {
            Ok(obj) => PyErr::from_value(obj),
            Err(_) => value_error(msg),
        },
        Err(_) => value_error(msg),
    }
}

/// Runs `f` without the GIL, turning a panic (a bug: the library is meant never to panic) into
/// a `RuntimeError` instead of letting it unwind into Python.
pub fn compute<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> crease::Result<T> + Send,
) -> PyResult<T> {
    let r = py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    match r {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_py_err(py, e)),
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(PyRuntimeError::new_err(format!(
                "internal error in crease (please report it): {what}"
            )))
        }
    }
}

/// An (n, 3) float64 array as points, refusing NaN and infinite coordinates (the CLI drops such
/// points when it reads a file; an array is refused, as its row numbers would otherwise shift).
pub fn points_of(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; 3]>> {
    let shape = a.shape();
    if shape[1] != 3 {
        return Err(value_error(format!(
            "{name}: expected an (n, 3) array, got shape ({}, {})",
            shape[0], shape[1]
        )));
    }
    let out: Vec<[f64; 3]> = match a.as_slice() {
        Ok(s) => s.as_chunks::<3>().0.to_vec(),
        Err(_) => a
            .as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect(),
    };
    if let Some(i) = out.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        return Err(value_error(format!(
            "{name}: row {i} has a NaN or infinite coordinate ({:?})",
            out[i]
        )));
    }
    Ok(out)
}

/// An (m, 3) int64 array of triangles over `n` vertices.
pub fn faces_of(a: &PyReadonlyArray2<'_, i64>, n: usize) -> PyResult<Vec<[u32; 3]>> {
    let shape = a.shape();
    if shape[1] != 3 {
        return Err(value_error(format!(
            "faces: expected an (m, 3) array of vertex indices, got shape ({}, {})",
            shape[0], shape[1]
        )));
    }
    let mut out = Vec::with_capacity(shape[0]);
    for (i, r) in a.as_array().rows().into_iter().enumerate() {
        let mut f = [0u32; 3];
        for (k, &v) in r.iter().enumerate() {
            if v < 0 || v as u64 >= n as u64 {
                return Err(value_error(format!(
                    "face {i} refers to vertex {v}, but there are {n} vertices"
                )));
            }
            f[k] = v as u32;
        }
        out.push(f);
    }
    Ok(out)
}

/// The CLI's check of the analysing commands (`load_shape`, [`crease::spatial::check_shape`]):
/// points that all coincide, or span beyond f64's squared distances. The message is the CLI's
/// without the file name.
pub fn check_shape(p: &[[f64; 3]]) -> PyResult<()> {
    crease::spatial::check_shape(p).map_err(|e| value_error(e.to_string()))
}

/// Points as an (n, 3) float64 array, without copying them.
pub fn points_array<'py>(py: Python<'py>, p: Vec<[f64; 3]>) -> PyResult<Bound<'py, PyAny>> {
    let n = p.len();
    Ok(PyArray1::from_vec(py, p.into_flattened())
        .reshape([n, 3])?
        .into_any())
}

/// Index triples / pairs as an (m, K) int64 array.
pub fn index_array<'py, const K: usize>(
    py: Python<'py>,
    v: &[[u32; K]],
) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<i64> = v.iter().flatten().map(|&i| i64::from(i)).collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([v.len(), K])?
        .into_any())
}

/// A 1-D array.
pub fn vec_array<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// An attribute's values as a 1-D array of its storage type (uint8, int32, float32, ...): the
/// values are held exactly, and writing them back keeps the kind.
pub fn attribute_array<'py>(py: Python<'py>, a: &Attribute) -> Bound<'py, PyAny> {
    macro_rules! cast {
        ($t:ty) => {
            vec_array(py, a.values.iter().map(|&v| v as $t).collect::<Vec<$t>>())
        };
    }
    match a.kind {
        ScalarKind::I8 => cast!(i8),
        ScalarKind::U8 => cast!(u8),
        ScalarKind::I16 => cast!(i16),
        ScalarKind::U16 => cast!(u16),
        ScalarKind::I32 => cast!(i32),
        ScalarKind::U32 => cast!(u32),
        ScalarKind::F32 => cast!(f32),
        ScalarKind::F64 => vec_array(py, a.values.clone()),
    }
}

/// Every attribute as a dict name -> array, in the file's order.
pub fn attributes_dict<'py>(py: Python<'py>, attrs: &Attributes) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for a in attrs {
        d.set_item(&a.name, attribute_array(py, a))?;
    }
    Ok(d)
}

/// A storage kind named as PLY does (`uchar`, `int`, `float`, `double`, ...).
pub fn kind_of(name: &str) -> PyResult<ScalarKind> {
    ScalarKind::from_ply_name(name)
        .ok_or_else(|| value_error(format!("unknown attribute kind {name:?}")))
}

/// An attribute from its name, PLY kind name and float64 values.
pub fn attribute_of(
    name: String,
    kind: &str,
    values: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Attribute> {
    Ok(Attribute {
        name,
        kind: kind_of(kind)?,
        values: values.as_array().to_vec(),
    })
}

/// A JSON value (a result serialised as the CLI serialises it) as Python objects: dicts,
/// lists, str, int, float, bool, None.
pub fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(json_to_py(py, x)?)?;
            }
            l.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// Any serialisable value as Python objects, through its JSON form (the CLI's `--json`).
pub fn to_py<'py>(py: Python<'py>, v: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let j = serde_json::to_value(v)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot serialise a result: {e}")))?;
    json_to_py(py, &j)
}

/// The polylines (point-index chains) as (m, 3) arrays of their vertices' positions and as
/// int64 index arrays.
pub fn polylines<'py>(
    py: Python<'py>,
    vertices: &[[f64; 3]],
    lines: &[Vec<u32>],
) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyList>)> {
    let pos = PyList::empty(py);
    let idx = PyList::empty(py);
    for l in lines {
        let p: Vec<[f64; 3]> = l
            .iter()
            .map(|&i| vertices.get(i as usize).copied().unwrap_or([f64::NAN; 3]))
            .collect();
        pos.append(points_array(py, p)?)?;
        idx.append(vec_array(
            py,
            l.iter().map(|&i| i64::from(i)).collect::<Vec<i64>>(),
        ))?;
    }
    Ok((pos, idx))
}

/// Reads a 2-D array argument that may be None.
pub fn opt_points(
    name: &str,
    a: Option<&PyReadonlyArray2<'_, f64>>,
) -> PyResult<Option<Vec<[f64; 3]>>> {
    a.map(|a| points_of(name, a)).transpose()
}

/// Points as a float64 array argument.
pub type Points<'py> = PyReadonlyArray2<'py, f64>;
/// Triangles as an int64 array argument.
pub type Faces<'py> = PyReadonlyArray2<'py, i64>;
