//! A cloud's attributes as columns, the way PDAL's dimensions travel with
//! the points: one column a dimension (intensity, return number,
//! classification, GPS time, colour, ring, extra bytes ...), each as long
//! as the cloud, named as PDAL names it (`Intensity`, `ReturnNumber`,
//! `GpsTime`, `Red` ...). A filter that drops points drops the same rows
//! of every column ([`Attributes::select`]); a filter that makes new
//! points says in its docs which row each new point takes its values from.

/// The values of one column, in the type the file stored them in.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Unsigned bytes (classification, return number, flags).
    U8(Vec<u8>),
    /// Signed bytes.
    I8(Vec<i8>),
    /// Unsigned 16-bit (intensity, colour, point source id).
    U16(Vec<u16>),
    /// Signed 16-bit.
    I16(Vec<i16>),
    /// Unsigned 32-bit.
    U32(Vec<u32>),
    /// Signed 32-bit.
    I32(Vec<i32>),
    /// Unsigned 64-bit.
    U64(Vec<u64>),
    /// Signed 64-bit.
    I64(Vec<i64>),
    /// Single precision (scan angle, a PCD field of type F4).
    F32(Vec<f32>),
    /// Double precision (GPS time).
    F64(Vec<f64>),
    /// Opaque records of `width` bytes a point (LAS extra bytes), kept
    /// byte for byte.
    Bytes {
        /// Bytes a point.
        width: usize,
        /// The rows, one after another.
        data: Vec<u8>,
    },
}

/// `$body` once for every typed arm of a [`Values`], with `$v` the vector.
macro_rules! each_typed {
    ($values:expr, $v:ident => $body:expr, bytes($w:ident, $d:ident) => $bytes:expr) => {
        match $values {
            Values::U8($v) => Values::U8($body),
            Values::I8($v) => Values::I8($body),
            Values::U16($v) => Values::U16($body),
            Values::I16($v) => Values::I16($body),
            Values::U32($v) => Values::U32($body),
            Values::I32($v) => Values::I32($body),
            Values::U64($v) => Values::U64($body),
            Values::I64($v) => Values::I64($body),
            Values::F32($v) => Values::F32($body),
            Values::F64($v) => Values::F64($body),
            Values::Bytes {
                width: $w,
                data: $d,
            } => $bytes,
        }
    };
}

impl Values {
    /// Number of rows.
    pub fn len(&self) -> usize {
        match self {
            Values::U8(v) => v.len(),
            Values::I8(v) => v.len(),
            Values::U16(v) => v.len(),
            Values::I16(v) => v.len(),
            Values::U32(v) => v.len(),
            Values::I32(v) => v.len(),
            Values::U64(v) => v.len(),
            Values::I64(v) => v.len(),
            Values::F32(v) => v.len(),
            Values::F64(v) => v.len(),
            Values::Bytes { width, data } => data.len().checked_div(*width).unwrap_or(0),
        }
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The rows `rows`, in that order.
    pub fn select(&self, rows: &[usize]) -> Values {
        each_typed!(self, v => rows.iter().map(|&i| v[i]).collect(), bytes(width, data) => {
            let w = *width;
            let mut out = Vec::with_capacity(rows.len() * w);
            for &i in rows {
                out.extend_from_slice(&data[i * w..(i + 1) * w]);
            }
            Values::Bytes { width: w, data: out }
        })
    }

    /// Row `i` as f64 (a `Bytes` row is NaN): for tables and tests.
    pub fn f64_at(&self, i: usize) -> f64 {
        match self {
            Values::U8(v) => f64::from(v[i]),
            Values::I8(v) => f64::from(v[i]),
            Values::U16(v) => f64::from(v[i]),
            Values::I16(v) => f64::from(v[i]),
            Values::U32(v) => f64::from(v[i]),
            Values::I32(v) => f64::from(v[i]),
            Values::U64(v) => v[i] as f64,
            Values::I64(v) => v[i] as f64,
            Values::F32(v) => f64::from(v[i]),
            Values::F64(v) => v[i],
            Values::Bytes { .. } => f64::NAN,
        }
    }

    /// Appends row `i`'s little-endian bytes to `out`.
    pub fn le_bytes_at(&self, i: usize, out: &mut Vec<u8>) {
        match self {
            Values::U8(v) => out.push(v[i]),
            Values::I8(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::U16(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::I16(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::U32(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::I32(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::U64(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::I64(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::F32(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::F64(v) => out.extend_from_slice(&v[i].to_le_bytes()),
            Values::Bytes { width, data } => {
                out.extend_from_slice(&data[i * width..(i + 1) * width])
            }
        }
    }

    /// Appends row `i` as text (floats the shortest that reads back the
    /// same; a `Bytes` row as its bytes, space separated) to `out`.
    pub fn text_at(&self, i: usize, out: &mut String) {
        use std::fmt::Write;
        let _ = match self {
            Values::U8(v) => write!(out, "{}", v[i]),
            Values::I8(v) => write!(out, "{}", v[i]),
            Values::U16(v) => write!(out, "{}", v[i]),
            Values::I16(v) => write!(out, "{}", v[i]),
            Values::U32(v) => write!(out, "{}", v[i]),
            Values::I32(v) => write!(out, "{}", v[i]),
            Values::U64(v) => write!(out, "{}", v[i]),
            Values::I64(v) => write!(out, "{}", v[i]),
            Values::F32(v) => write!(out, "{:?}", v[i]),
            Values::F64(v) => write!(out, "{:?}", v[i]),
            Values::Bytes { width, data } => {
                let row = &data[i * width..(i + 1) * width];
                let words: Vec<String> = row.iter().map(|b| b.to_string()).collect();
                write!(out, "{}", words.join(" "))
            }
        };
    }

    /// PCD's TYPE, SIZE and COUNT for this column.
    pub fn pcd_type(&self) -> (char, usize, usize) {
        match self {
            Values::U8(_) => ('U', 1, 1),
            Values::I8(_) => ('I', 1, 1),
            Values::U16(_) => ('U', 2, 1),
            Values::I16(_) => ('I', 2, 1),
            Values::U32(_) => ('U', 4, 1),
            Values::I32(_) => ('I', 4, 1),
            Values::U64(_) => ('U', 8, 1),
            Values::I64(_) => ('I', 8, 1),
            Values::F32(_) => ('F', 4, 1),
            Values::F64(_) => ('F', 8, 1),
            Values::Bytes { width, .. } => ('U', 1, *width),
        }
    }

    /// An empty column of PCD's TYPE `kind` and SIZE `size` (`count`
    /// values a point: only bytes may have more than one).
    pub(crate) fn for_pcd(kind: char, size: usize, count: usize) -> Option<Values> {
        Some(match (kind, size, count) {
            ('U' | 'I', 1, w) if w > 1 => Values::Bytes {
                width: w,
                data: Vec::new(),
            },
            (_, _, c) if c != 1 => return None,
            ('U', 1, _) => Values::U8(Vec::new()),
            ('I', 1, _) => Values::I8(Vec::new()),
            ('U', 2, _) => Values::U16(Vec::new()),
            ('I', 2, _) => Values::I16(Vec::new()),
            ('U', 4, _) => Values::U32(Vec::new()),
            ('I', 4, _) => Values::I32(Vec::new()),
            ('U', 8, _) => Values::U64(Vec::new()),
            ('I', 8, _) => Values::I64(Vec::new()),
            ('F', 4, _) => Values::F32(Vec::new()),
            ('F', 8, _) => Values::F64(Vec::new()),
            _ => return None,
        })
    }

    /// Appends a row from its little-endian bytes (as many as the type
    /// takes; `big_endian` for PLY's other order).
    pub(crate) fn push_bytes(&mut self, b: &[u8], big_endian: bool) {
        macro_rules! num {
            ($v:ident, $t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                $v.push(if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                })
            }};
        }
        match self {
            Values::U8(v) => v.push(b[0]),
            Values::I8(v) => v.push(b[0] as i8),
            Values::U16(v) => num!(v, u16, 2),
            Values::I16(v) => num!(v, i16, 2),
            Values::U32(v) => num!(v, u32, 4),
            Values::I32(v) => num!(v, i32, 4),
            Values::U64(v) => num!(v, u64, 8),
            Values::I64(v) => num!(v, i64, 8),
            Values::F32(v) => num!(v, f32, 4),
            Values::F64(v) => num!(v, f64, 8),
            Values::Bytes { width, data } => data.extend_from_slice(&b[..*width]),
        }
    }

    /// Appends a row from its text (the value's own type: an integer must
    /// be one, in range); the reason when it is not.
    pub(crate) fn push_text(&mut self, words: &[&str]) -> Result<(), String> {
        fn parse<T: std::str::FromStr>(w: &str) -> Result<T, String> {
            w.parse::<T>()
                .map_err(|_| format!("{w:?} is not a value of the field's type"))
        }
        let w = words.first().copied().unwrap_or("");
        match self {
            Values::U8(v) => v.push(parse(w)?),
            Values::I8(v) => v.push(parse(w)?),
            Values::U16(v) => v.push(parse(w)?),
            Values::I16(v) => v.push(parse(w)?),
            Values::U32(v) => v.push(parse(w)?),
            Values::I32(v) => v.push(parse(w)?),
            Values::U64(v) => v.push(parse(w)?),
            Values::I64(v) => v.push(parse(w)?),
            Values::F32(v) => v.push(parse(w)?),
            Values::F64(v) => v.push(parse(w)?),
            Values::Bytes { width, data } => {
                for k in 0..*width {
                    data.push(parse(words.get(k).copied().unwrap_or(""))?);
                }
            }
        }
        Ok(())
    }

    /// The type's name as PDAL prints it (`uint8`, `float`, `double`,
    /// `bytes`).
    pub fn type_name(&self) -> &'static str {
        match self {
            Values::U8(_) => "uint8",
            Values::I8(_) => "int8",
            Values::U16(_) => "uint16",
            Values::I16(_) => "int16",
            Values::U32(_) => "uint32",
            Values::I32(_) => "int32",
            Values::U64(_) => "uint64",
            Values::I64(_) => "int64",
            Values::F32(_) => "float",
            Values::F64(_) => "double",
            Values::Bytes { .. } => "bytes",
        }
    }
}

/// PDAL's dimension names that a PLY property or a text header may spell
/// in another case.
const PDAL_NAMES: [&str; 12] = [
    "Intensity",
    "Red",
    "Green",
    "Blue",
    "Alpha",
    "Classification",
    "ReturnNumber",
    "NumberOfReturns",
    "GpsTime",
    "PointSourceId",
    "UserData",
    "ScanAngleRank",
];

/// A column's name as PDAL names the dimension (`red` → `Red`, any case);
/// a name PDAL has no dimension for is kept as given.
pub(crate) fn pdal_name(name: &str) -> String {
    PDAL_NAMES
        .iter()
        .find(|n| n.eq_ignore_ascii_case(name))
        .map_or_else(|| name.to_string(), |n| (*n).to_string())
}

/// One named column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// The dimension's name, as PDAL names it (`Intensity`, `GpsTime`).
    pub name: String,
    /// Its rows.
    pub values: Values,
}

/// The attribute columns of a cloud, in the order the file gave them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attributes {
    columns: Vec<Column>,
}

impl Attributes {
    /// No columns.
    pub fn new() -> Self {
        Self::default()
    }

    /// The columns, in order.
    pub fn columns(&self) -> &[Column] {
        &self.columns
    }

    /// Whether there are no columns.
    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }

    /// The column named `name`.
    pub fn get(&self, name: &str) -> Option<&Values> {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| &c.values)
    }

    /// Adds (or replaces) the column `name`.
    pub fn insert(&mut self, name: impl Into<String>, values: Values) {
        let name = name.into();
        match self.columns.iter_mut().find(|c| c.name == name) {
            Some(c) => c.values = values,
            None => self.columns.push(Column { name, values }),
        }
    }

    /// Removes and returns the column `name`.
    pub fn remove(&mut self, name: &str) -> Option<Values> {
        let at = self.columns.iter().position(|c| c.name == name)?;
        Some(self.columns.remove(at).values)
    }

    /// The rows `rows` of every column, in that order: what a filter that
    /// drops points (or picks a point a voxel) keeps.
    pub fn select(&self, rows: &[usize]) -> Attributes {
        Attributes {
            columns: self
                .columns
                .iter()
                .map(|c| Column {
                    name: c.name.clone(),
                    values: c.values.select(rows),
                })
                .collect(),
        }
    }

    /// The first column whose length is not `n`, as (name, length).
    pub fn mismatch(&self, n: usize) -> Option<(&str, usize)> {
        self.columns
            .iter()
            .find(|c| c.values.len() != n)
            .map(|c| (c.name.as_str(), c.values.len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selecting_rows_takes_the_same_rows_of_every_column() {
        let mut a = Attributes::new();
        a.insert("Intensity", Values::U16(vec![10, 11, 12, 13]));
        a.insert("GpsTime", Values::F64(vec![0.5, 1.5, 2.5, 3.5]));
        a.insert(
            "ExtraBytes",
            Values::Bytes {
                width: 2,
                data: vec![0, 1, 2, 3, 4, 5, 6, 7],
            },
        );
        let s = a.select(&[3, 1]);
        assert_eq!(s.get("Intensity"), Some(&Values::U16(vec![13, 11])));
        assert_eq!(s.get("GpsTime"), Some(&Values::F64(vec![3.5, 1.5])));
        assert_eq!(
            s.get("ExtraBytes"),
            Some(&Values::Bytes {
                width: 2,
                data: vec![6, 7, 2, 3]
            })
        );
        assert_eq!(s.mismatch(2), None);
        assert_eq!(s.mismatch(3), Some(("Intensity", 2)));
    }
}
