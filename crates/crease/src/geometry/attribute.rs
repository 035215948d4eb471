//! Named per-element attributes (per point, per face, per edge).
//!
//! Values are stored as `f64`, which holds every PLY scalar type exactly (the widest integer
//! types in PLY are 32-bit), together with the scalar kind they are written out as. A detector's
//! output (`sharp`, `sharpness`, `label`, ...) is an attribute and travels with the points.

use crate::{Error, Result};

/// The storage type an attribute is written as (PLY property types).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScalarKind {
    /// Signed 8-bit integer (`char`).
    I8,
    /// Unsigned 8-bit integer (`uchar`).
    U8,
    /// Signed 16-bit integer (`short`).
    I16,
    /// Unsigned 16-bit integer (`ushort`).
    U16,
    /// Signed 32-bit integer (`int`).
    I32,
    /// Unsigned 32-bit integer (`uint`).
    U32,
    /// 32-bit float (`float`).
    F32,
    /// 64-bit float (`double`).
    F64,
}

impl ScalarKind {
    /// True for the integer kinds.
    pub fn is_integer(self) -> bool {
        !matches!(self, ScalarKind::F32 | ScalarKind::F64)
    }

    /// Size in bytes of one value.
    pub fn size(self) -> usize {
        match self {
            ScalarKind::I8 | ScalarKind::U8 => 1,
            ScalarKind::I16 | ScalarKind::U16 => 2,
            ScalarKind::I32 | ScalarKind::U32 | ScalarKind::F32 => 4,
            ScalarKind::F64 => 8,
        }
    }

    /// The canonical PLY name (`uchar`, `int`, `float`, ...).
    pub fn ply_name(self) -> &'static str {
        match self {
            ScalarKind::I8 => "char",
            ScalarKind::U8 => "uchar",
            ScalarKind::I16 => "short",
            ScalarKind::U16 => "ushort",
            ScalarKind::I32 => "int",
            ScalarKind::U32 => "uint",
            ScalarKind::F32 => "float",
            ScalarKind::F64 => "double",
        }
    }

    /// Parses a PLY type name, including the sized aliases (`uint8`, `float32`, ...).
    pub fn from_ply_name(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => ScalarKind::I8,
            "uchar" | "uint8" => ScalarKind::U8,
            "short" | "int16" => ScalarKind::I16,
            "ushort" | "uint16" => ScalarKind::U16,
            "int" | "int32" => ScalarKind::I32,
            "uint" | "uint32" => ScalarKind::U32,
            "float" | "float32" => ScalarKind::F32,
            "double" | "float64" => ScalarKind::F64,
            _ => return None,
        })
    }
}

/// One named column of per-element values.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// Property name, e.g. `sharpness`.
    pub name: String,
    /// How the values are written out.
    pub kind: ScalarKind,
    /// One value per element, in element order.
    pub values: Vec<f64>,
}

impl Attribute {
    /// A float attribute (written as `float`).
    pub fn float(name: impl Into<String>, values: Vec<f64>) -> Self {
        Attribute {
            name: name.into(),
            kind: ScalarKind::F32,
            values,
        }
    }

    /// An integer attribute (written as `int`).
    pub fn int(name: impl Into<String>, values: impl IntoIterator<Item = i64>) -> Self {
        Attribute {
            name: name.into(),
            kind: ScalarKind::I32,
            values: values.into_iter().map(|v| v as f64).collect(),
        }
    }

    /// A 0/1 flag attribute (written as `uchar`).
    pub fn flag(name: impl Into<String>, values: impl IntoIterator<Item = bool>) -> Self {
        Attribute {
            name: name.into(),
            kind: ScalarKind::U8,
            values: values
                .into_iter()
                .map(|v| if v { 1.0 } else { 0.0 })
                .collect(),
        }
    }

    /// The values as integers (rounded toward zero).
    pub fn as_i64(&self) -> Vec<i64> {
        self.values.iter().map(|&v| v as i64).collect()
    }
}

/// An ordered set of attributes over `len` elements, looked up by name.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attributes {
    items: Vec<Attribute>,
}

impl Attributes {
    /// No attributes.
    pub fn new() -> Self {
        Self::default()
    }

    /// The attribute named `name`.
    pub fn get(&self, name: &str) -> Option<&Attribute> {
        self.items.iter().find(|a| a.name == name)
    }

    /// Mutable access to the attribute named `name`.
    pub fn get_mut(&mut self, name: &str) -> Option<&mut Attribute> {
        self.items.iter_mut().find(|a| a.name == name)
    }

    /// Adds `attr`, replacing an attribute of the same name. Fails if its length is not `len`.
    pub fn insert(&mut self, len: usize, attr: Attribute) -> Result<()> {
        if attr.values.len() != len {
            return Err(Error::InvalidArgument(format!(
                "attribute {:?} has {} values for {} elements",
                attr.name,
                attr.values.len(),
                len
            )));
        }
        match self.items.iter_mut().find(|a| a.name == attr.name) {
            Some(slot) => *slot = attr,
            None => self.items.push(attr),
        }
        Ok(())
    }

    /// Adds many attributes at once, each replacing an attribute of the same name (a later one
    /// of `attrs` wins over an earlier one): linear in their number, where one [`insert`] after
    /// another is quadratic (a wide text file took over a minute to read, see
    /// `docs/experiments/io-readers.md`).
    ///
    /// [`insert`]: Attributes::insert
    pub fn extend(&mut self, len: usize, attrs: Vec<Attribute>) -> Result<()> {
        if let Some(a) = attrs.iter().find(|a| a.values.len() != len) {
            return Err(Error::InvalidArgument(format!(
                "attribute {:?} has {} values for {} elements",
                a.name,
                a.values.len(),
                len
            )));
        }
        let mut index: std::collections::HashMap<String, usize> = self
            .items
            .iter()
            .enumerate()
            .map(|(i, a)| (a.name.clone(), i))
            .collect();
        for attr in attrs {
            match index.get(&attr.name) {
                Some(&i) => self.items[i] = attr,
                None => {
                    index.insert(attr.name.clone(), self.items.len());
                    self.items.push(attr);
                }
            }
        }
        Ok(())
    }

    /// Removes and returns the attribute named `name`.
    pub fn remove(&mut self, name: &str) -> Option<Attribute> {
        let i = self.items.iter().position(|a| a.name == name)?;
        Some(self.items.remove(i))
    }

    /// The attributes in insertion order.
    pub fn iter(&self) -> std::slice::Iter<'_, Attribute> {
        self.items.iter()
    }

    /// Number of attributes.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True if there are no attributes.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Keeps, in every attribute, only the elements whose `keep` flag is true.
    pub fn retain_elements(&mut self, keep: &[bool]) {
        for a in &mut self.items {
            let mut i = 0;
            a.values.retain(|_| {
                let k = keep[i];
                i += 1;
                k
            });
        }
    }

    /// Reorders / selects elements: element `i` of the result is element `index[i]` of self.
    pub fn select(&self, index: &[usize]) -> Attributes {
        Attributes {
            items: self
                .items
                .iter()
                .map(|a| Attribute {
                    name: a.name.clone(),
                    kind: a.kind,
                    values: index.iter().map(|&i| a.values[i]).collect(),
                })
                .collect(),
        }
    }
}

impl<'a> IntoIterator for &'a Attributes {
    type Item = &'a Attribute;
    type IntoIter = std::slice::Iter<'a, Attribute>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `extend` is `insert` after `insert`: a name already there keeps its place and takes the
    /// new values, a later duplicate wins, a wrong length is an error that changes nothing.
    #[test]
    fn extend_equals_repeated_inserts() {
        let a = |name: &str, v: f64| Attribute::float(name, vec![v; 2]);
        let batch = vec![a("b", 2.0), a("c", 3.0), a("a", 4.0), a("c", 5.0)];
        let mut one = Attributes::new();
        one.insert(2, a("a", 1.0)).expect("insert");
        let mut many = one.clone();
        for x in batch.clone() {
            one.insert(2, x).expect("insert");
        }
        many.extend(2, batch).expect("extend");
        assert_eq!(one, many);
        let names: Vec<&str> = many.iter().map(|x| x.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "c"]);
        assert_eq!(many.get("c").expect("c").values, vec![5.0; 2]);
        let before = many.clone();
        assert!(many.extend(2, vec![a("d", 1.0), a("e", 1.0)]).is_ok());
        let mut bad = before.clone();
        let short = Attribute::float("f", vec![1.0]);
        assert!(bad.extend(2, vec![a("g", 1.0), short]).is_err());
        assert_eq!(bad, before);
    }
}
