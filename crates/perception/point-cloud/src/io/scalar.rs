//! Scalar types shared by the PCD and PLY layouts: their sizes and how one
//! value is turned into an `f32` coordinate.

/// One numeric type of a PCD field or a PLY property.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    /// Size of one value (bytes).
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    /// Whether the type is an integer (PLY list counts must be).
    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The PCD type from its TYPE letter and SIZE.
    pub(crate) fn from_pcd(kind: char, size: usize) -> Option<Scalar> {
        Some(match (kind, size) {
            ('I', 1) => Scalar::I8,
            ('U', 1) => Scalar::U8,
            ('I', 2) => Scalar::I16,
            ('U', 2) => Scalar::U16,
            ('I', 4) => Scalar::I32,
            ('U', 4) => Scalar::U32,
            ('I', 8) => Scalar::I64,
            ('U', 8) => Scalar::U64,
            ('F', 4) => Scalar::F32,
            ('F', 8) => Scalar::F64,
            _ => return None,
        })
    }

    /// The PLY type from its name (both the classic and the sized spellings).
    pub(crate) fn from_ply(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// The value at the start of `b` (at least `self.size()` bytes) as an
    /// `f32`, rounded once (integers and doubles are converted directly).
    #[inline]
    pub(crate) fn to_f32(self, b: &[u8], big_endian: bool) -> f32 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                if big_endian {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }
            }};
        }
        match self {
            Scalar::I8 => b[0] as i8 as f32,
            Scalar::U8 => b[0] as f32,
            Scalar::I16 => get!(i16, 2) as f32,
            Scalar::U16 => get!(u16, 2) as f32,
            Scalar::I32 => get!(i32, 4) as f32,
            Scalar::U32 => get!(u32, 4) as f32,
            Scalar::I64 => get!(i64, 8) as f32,
            Scalar::U64 => get!(u64, 8) as f32,
            Scalar::F32 => get!(f32, 4),
            Scalar::F64 => get!(f64, 8) as f32,
        }
    }

    /// The value at the start of `b` as an `f64` (exact for every type but
    /// 64-bit integers beyond 2⁵³).
    #[inline]
    pub(crate) fn to_f64(self, b: &[u8], big_endian: bool) -> f64 {
        match self {
            Scalar::F64 => {
                let mut a = [0u8; 8];
                a.copy_from_slice(&b[..8]);
                if big_endian {
                    f64::from_be_bytes(a)
                } else {
                    f64::from_le_bytes(a)
                }
            }
            Scalar::I64 | Scalar::U64 => self.to_i128(b, big_endian) as f64,
            other => f64::from(other.to_f32(b, big_endian)),
        }
    }

    /// A text value as an `f64` (floats at the text's own precision;
    /// integers checked as [`Scalar::parse_f32`] checks them).
    pub(crate) fn parse_f64(self, s: &str) -> Result<f64, String> {
        match self {
            Scalar::F32 | Scalar::F64 => s.parse::<f64>().map_err(|_| "not a number".to_string()),
            _ => self.parse_f32(s).map(f64::from),
        }
    }

    /// PCD's TYPE letter.
    pub(crate) fn pcd_kind(self) -> char {
        match self {
            Scalar::I8 | Scalar::I16 | Scalar::I32 | Scalar::I64 => 'I',
            Scalar::U8 | Scalar::U16 | Scalar::U32 | Scalar::U64 => 'U',
            Scalar::F32 | Scalar::F64 => 'F',
        }
    }

    /// The value at the start of `b` as an unsigned count (PLY list
    /// lengths); `None` for a negative value or a float type.
    pub(crate) fn to_count(self, b: &[u8], big_endian: bool) -> Option<u64> {
        if !self.is_integer() {
            return None;
        }
        let v = self.to_i128(b, big_endian);
        u64::try_from(v).ok()
    }

    fn to_i128(self, b: &[u8], big_endian: bool) -> i128 {
        let n = self.size();
        let mut a = [0u8; 8];
        let signed = matches!(self, Scalar::I8 | Scalar::I16 | Scalar::I32 | Scalar::I64);
        if big_endian {
            a[8 - n..].copy_from_slice(&b[..n]);
            let raw = u64::from_be_bytes(a);
            sign_extend(raw, n, signed)
        } else {
            a[..n].copy_from_slice(&b[..n]);
            let raw = u64::from_le_bytes(a);
            sign_extend(raw, n, signed)
        }
    }

    /// The values an integer type holds, inclusive, and its name (None
    /// for the float types).
    fn int_range(self) -> Option<(i128, i128, &'static str)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into(), "an 8-bit integer"),
            Scalar::U8 => (0, u8::MAX.into(), "an unsigned 8-bit integer"),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into(), "a 16-bit integer"),
            Scalar::U16 => (0, u16::MAX.into(), "an unsigned 16-bit integer"),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into(), "a 32-bit integer"),
            Scalar::U32 => (0, u32::MAX.into(), "an unsigned 32-bit integer"),
            Scalar::I64 => (i64::MIN.into(), i64::MAX.into(), "a 64-bit integer"),
            Scalar::U64 => (0, u64::MAX.into(), "an unsigned 64-bit integer"),
            Scalar::F32 | Scalar::F64 => return None,
        })
    }

    /// A text value of this type as an `f32` (one rounding step), or why
    /// it is not one: not a number, or for an integer type a fraction or a
    /// value the type cannot hold (written by sloppy tools, "3.0" is
    /// accepted; 1.5, 300 for a uchar and -5 for an unsigned type are not:
    /// reading them would return what the file does not say).
    pub(crate) fn parse_f32(self, s: &str) -> Result<f32, String> {
        let Some((lo, hi, name)) = self.int_range() else {
            let v = match self {
                Scalar::F32 => s.parse::<f32>().ok(),
                _ => s.parse::<f64>().ok().map(|v| v as f32),
            };
            return v.ok_or_else(|| "not a number".to_string());
        };
        let v = match s.parse::<i128>() {
            Ok(v) => v,
            Err(_) => {
                let f = s.parse::<f64>().map_err(|_| format!("not {name}"))?;
                if !(f.is_finite() && f.fract() == 0.0) {
                    return Err(format!("the field is {name}, which holds no fraction"));
                }
                // Beyond every integer type: the range check refuses it.
                f.clamp(-1e20, 1e20) as i128
            }
        };
        if v < lo || v > hi {
            return Err(format!("the field is {name}, which holds {lo} to {hi}"));
        }
        Ok(v as f32)
    }

    /// A text list count.
    pub(crate) fn parse_count(self, s: &str) -> Option<u64> {
        if !self.is_integer() {
            return None;
        }
        s.parse::<u64>().ok()
    }
}

fn sign_extend(raw: u64, n: usize, signed: bool) -> i128 {
    let bits = 8 * n as u32;
    if signed && bits < 64 && raw & (1 << (bits - 1)) != 0 {
        i128::from(raw) - (1i128 << bits)
    } else if signed && bits == 64 {
        i128::from(raw as i64)
    } else {
        i128::from(raw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_integers_must_fit_their_type_and_have_no_fraction() {
        assert_eq!(Scalar::U8.parse_f32("255"), Ok(255.0));
        assert_eq!(Scalar::U8.parse_f32("3.0"), Ok(3.0));
        assert_eq!(Scalar::I8.parse_f32("-128"), Ok(-128.0));
        assert_eq!(
            Scalar::U64.parse_f32("18446744073709551615"),
            Ok(1.8446744e19)
        );
        for (ty, s, why) in [
            (Scalar::U8, "300", "0 to 255"),
            (Scalar::U8, "-5", "0 to 255"),
            (Scalar::U8, "1.5", "no fraction"),
            (Scalar::I8, "-129", "-128 to 127"),
            (Scalar::U16, "1e30", "0 to 65535"),
            (Scalar::U16, "inf", "no fraction"),
            (Scalar::I32, "x", "not a 32-bit integer"),
            (Scalar::F32, "x", "not a number"),
        ] {
            let e = ty.parse_f32(s).unwrap_err();
            assert!(e.contains(why), "{ty:?} {s}: {e}");
        }
    }

    #[test]
    fn decodes_each_type_in_both_byte_orders() {
        assert_eq!(Scalar::I8.to_f32(&[0xff], false), -1.0);
        assert_eq!(Scalar::U8.to_f32(&[0xff], true), 255.0);
        assert_eq!(Scalar::I16.to_f32(&(-300i16).to_be_bytes(), true), -300.0);
        assert_eq!(Scalar::U16.to_f32(&60000u16.to_le_bytes(), false), 60000.0);
        assert_eq!(Scalar::I32.to_f32(&(-7i32).to_le_bytes(), false), -7.0);
        assert_eq!(Scalar::U32.to_f32(&7u32.to_be_bytes(), true), 7.0);
        assert_eq!(Scalar::F64.to_f32(&0.5f64.to_be_bytes(), true), 0.5);
        assert_eq!(Scalar::F32.to_f32(&1.25f32.to_le_bytes(), false), 1.25);
        assert_eq!(Scalar::I16.to_count(&(-1i16).to_le_bytes(), false), None);
        assert_eq!(Scalar::U8.to_count(&[200], false), Some(200));
        assert_eq!(Scalar::I32.to_count(&5i32.to_be_bytes(), true), Some(5));
        assert_eq!(Scalar::F32.to_count(&[0, 0, 0, 0], true), None);
    }
}
