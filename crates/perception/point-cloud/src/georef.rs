//! What a file said about its coordinates: the coordinate system (an EPSG
//! code, WKT, its linear unit) and, for LAS/LAZ, the header it was read
//! with (version, point format, scale, offset, every VLR), so that a cloud
//! read and written again keeps its CRS, point format and precision.

use std::fmt;

/// GeoTIFF key: the model type (1 projected, 2 geographic, 3 geocentric).
const GT_MODEL_TYPE: u16 = 1024;
/// GeoTIFF key: the geographic CRS's EPSG code.
const GEOGRAPHIC_TYPE: u16 = 2048;
/// GeoTIFF key: the projected CRS's EPSG code.
const PROJECTED_CS_TYPE: u16 = 3072;
/// GeoTIFF key: the projected CRS's linear unit (EPSG unit code).
const PROJ_LINEAR_UNITS: u16 = 3076;
/// GeoTIFF key: the geographic CRS's angular unit.
const GEOG_ANGULAR_UNITS: u16 = 2054;
/// GeoTIFF key: the vertical CRS's linear unit (EPSG unit code).
const VERTICAL_UNITS: u16 = 4099;
/// GeoTIFF model type of a geographic (degree) CRS.
const MODEL_GEOGRAPHIC: u16 = 2;
/// GeoTIFF "user-defined" code: no EPSG code.
const USER_DEFINED: u16 = 32767;

/// A CRS's linear unit, as far as the file tells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Unit {
    /// The file does not say (or names a unit not listed here).
    #[default]
    Unknown,
    /// Metres (EPSG 9001).
    Metre,
    /// International feet, 0.3048 m (EPSG 9002).
    Foot,
    /// US survey feet, 1200/3937 m (EPSG 9003).
    UsSurveyFoot,
    /// Degrees of a geographic CRS: not a length.
    Degree,
}

impl Unit {
    /// Metres a unit; `None` for degrees and an unknown unit.
    pub fn metres(self) -> Option<f64> {
        match self {
            Unit::Metre => Some(1.0),
            Unit::Foot => Some(0.3048),
            Unit::UsSurveyFoot => Some(1200.0 / 3937.0),
            Unit::Degree | Unit::Unknown => None,
        }
    }

    /// The unit from its EPSG code.
    pub fn from_epsg(code: u16) -> Unit {
        match code {
            9001 => Unit::Metre,
            9002 => Unit::Foot,
            9003 => Unit::UsSurveyFoot,
            9102 | 9122 => Unit::Degree,
            _ => Unit::Unknown,
        }
    }

    /// The units a WKT string names for x and y, and for z: a compound
    /// CRS (`COMPD_CS`, `COMPOUNDCRS`) gives its horizontal part's unit and
    /// its vertical part's (`VERT_CS`, `VERTCRS`); any other gives
    /// [`Unit::from_wkt`] and an unknown vertical unit.
    pub fn from_wkt_xyz(wkt: &str) -> (Unit, Unit) {
        let upper = wkt.trim_start().to_ascii_uppercase();
        if !(upper.starts_with("COMPD_CS") || upper.starts_with("COMPOUNDCRS")) {
            return (Unit::from_wkt(wkt), Unit::Unknown);
        }
        let vertical_at = upper.find("VERT_CS[").or_else(|| upper.find("VERTCRS["));
        let horizontal_at = ["PROJCS[", "PROJCRS[", "GEOGCS[", "GEOGCRS["]
            .iter()
            .filter_map(|k| upper.find(k))
            .min();
        let horizontal = match (horizontal_at, vertical_at) {
            (Some(h), Some(v)) if h < v => Unit::from_wkt(&upper[h..v]),
            (Some(h), _) => Unit::from_wkt(&upper[h..]),
            _ => Unit::Unknown,
        };
        let vertical = vertical_at.map_or(Unit::Unknown, |v| {
            let part = &upper[v..];
            part.find("UNIT[").map_or(Unit::Unknown, |at| {
                Unit::named(part[at..].split('"').nth(1).unwrap_or(""))
            })
        });
        (horizontal, vertical)
    }

    /// The unit a WKT string names for its axes: the last `UNIT[...]` of a
    /// projected CRS's own (outside its base geographic CRS), or degrees
    /// for a geographic CRS.
    pub fn from_wkt(wkt: &str) -> Unit {
        let t = wkt.trim_start();
        let upper = t.to_ascii_uppercase();
        if upper.starts_with("GEOGCS") || upper.starts_with("GEOGCRS") {
            return Unit::Degree;
        }
        if !(upper.starts_with("PROJCS") || upper.starts_with("PROJCRS")) {
            return Unit::Unknown;
        }
        // The projected CRS's own unit comes after its base CRS closes.
        let Some(at) = upper.rfind("UNIT[").or_else(|| upper.rfind("LENGTHUNIT[")) else {
            return Unit::Unknown;
        };
        Unit::named(upper[at..].split('"').nth(1).unwrap_or(""))
    }

    /// The unit a WKT `UNIT["NAME", ...]` names (upper case).
    fn named(name: &str) -> Unit {
        match name {
            "METRE" | "METER" | "METRES" | "METERS" => Unit::Metre,
            "US SURVEY FOOT" | "FOOT_US" | "US_SURVEY_FOOT" | "U.S. SURVEY FOOT" => {
                Unit::UsSurveyFoot
            }
            "FOOT" | "INTERNATIONAL FOOT" | "FOOT_INTL" => Unit::Foot,
            _ => Unit::Unknown,
        }
    }

    /// Its name in messages and summaries.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Unknown => "unknown",
            Unit::Metre => "metre",
            Unit::Foot => "foot",
            Unit::UsSurveyFoot => "US survey foot",
            Unit::Degree => "degree",
        }
    }
}

/// The coordinate system a file states.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Crs {
    /// The horizontal CRS's EPSG code, when the file gives one.
    pub epsg: Option<u32>,
    /// The WKT, when the file gives one.
    pub wkt: Option<String>,
    /// The linear unit of x and y.
    pub unit: Unit,
    /// The linear unit of z where the file states one of its own (a
    /// compound CRS's vertical part, or GeoTIFF's vertical unit key);
    /// unknown where it does not, and z is then taken in `unit`
    /// ([`Crs::z_unit`]).
    pub vertical: Unit,
}

impl Crs {
    /// Whether the file states no CRS at all.
    pub fn is_unknown(&self) -> bool {
        self.epsg.is_none() && self.wkt.is_none() && self.unit == Unit::Unknown
    }

    /// The unit of z: the vertical unit stated, else that of x and y.
    pub fn z_unit(&self) -> Unit {
        match self.vertical {
            Unit::Unknown => self.unit,
            v => v,
        }
    }

    /// Whether x and y are degrees of longitude and latitude.
    pub fn is_geographic(&self) -> bool {
        self.unit == Unit::Degree
    }
}

impl fmt::Display for Crs {
    /// `EPSG:26910 (metre)`, `WKT (US survey foot)`, `WKT (metre, z in US
    /// survey foot)` or `none stated`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let z = match self.z_unit() {
            z if z == self.unit => String::new(),
            z => format!(", z in {}", z.name()),
        };
        match (self.epsg, &self.wkt) {
            (Some(code), _) => write!(f, "EPSG:{code} ({}{z})", self.unit.name()),
            (None, Some(_)) => write!(f, "WKT ({}{z})", self.unit.name()),
            (None, None) if self.unit != Unit::Unknown => write!(f, "{}{z}", self.unit.name()),
            (None, None) => f.write_str("none stated"),
        }
    }
}

/// The LAS header a cloud was read with, written back with it.
#[derive(Debug, Clone, PartialEq)]
pub struct LasLayout(pub(crate) las::Header);

impl LasLayout {
    /// (major, minor) version.
    pub fn version(&self) -> (u8, u8) {
        let v = self.0.version();
        (v.major, v.minor)
    }

    /// The point format number (0–10).
    pub fn point_format(&self) -> u8 {
        self.0.point_format().to_u8().unwrap_or(0)
    }

    /// Scale per axis (the file's unit a step).
    pub fn scale(&self) -> [f64; 3] {
        let t = self.0.transforms();
        [t.x.scale, t.y.scale, t.z.scale]
    }

    /// Offset per axis.
    pub fn offset(&self) -> [f64; 3] {
        let t = self.0.transforms();
        [t.x.offset, t.y.offset, t.z.offset]
    }

    /// Bytes of one point record ([`crate::io::read_chunks_with`]'s rows).
    pub fn record_len(&self) -> usize {
        usize::from(self.0.point_format().len())
    }

    /// Whether points of `other` have the same fields as this layout's:
    /// the same point format and extra bytes (rows of one decode as the
    /// other's).
    pub fn same_fields(&self, other: &LasLayout) -> bool {
        self.0.point_format() == other.0.point_format()
    }

    /// The attributes of `rows`, point records as this layout lays them
    /// out (as [`crate::io::read_chunks_with`] hands them on), as the
    /// columns a cloud read from the file carries.
    pub fn attributes_of_rows(&self, rows: &[u8]) -> Result<crate::Attributes, String> {
        let format = *self.0.point_format();
        let transforms = *self.0.transforms();
        let len = self.record_len();
        if len == 0 || !rows.len().is_multiple_of(len) {
            return Err(format!(
                "{} bytes are not whole records of {len} bytes (point format {})",
                rows.len(),
                self.point_format()
            ));
        }
        let mut cols = crate::io::las_columns::LasColumns::for_format(&format);
        for r in rows.chunks_exact(len) {
            let raw = las::raw::Point::read_from(r, &format).map_err(|e| e.to_string())?;
            cols.push(&las::Point::new(raw, &transforms));
        }
        Ok(cols.into_attributes())
    }
}

/// What a file said of its coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Georef {
    /// The coordinate system.
    pub crs: Crs,
    /// The LAS header read, for LAS and LAZ.
    pub las: Option<LasLayout>,
    /// The sensor's pose a PCD file states (`VIEWPOINT`), where it is not
    /// the identity: written back to PCD, turned with the cloud by a
    /// levelling.
    pub viewpoint: Option<Viewpoint>,
}

/// PCL's viewpoint: where the sensor was and how it was turned, in the
/// cloud's frame (PCD's `VIEWPOINT tx ty tz qw qx qy qz`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewpoint {
    /// Position (tx, ty, tz), the file's coordinates.
    pub position: [f64; 3],
    /// Orientation as a unit quaternion (qw, qx, qy, qz).
    pub orientation: [f64; 4],
}

impl Viewpoint {
    /// The identity pose PCL writes when it knows none.
    pub const IDENTITY: Viewpoint = Viewpoint {
        position: [0.0; 3],
        orientation: [1.0, 0.0, 0.0, 0.0],
    };

    /// From PCD's seven numbers; `None` for the identity.
    pub fn from_pcd(v: [f64; 7]) -> Option<Self> {
        let vp = Viewpoint {
            position: [v[0], v[1], v[2]],
            orientation: [v[3], v[4], v[5], v[6]],
        };
        (vp != Self::IDENTITY).then_some(vp)
    }

    /// PCD's `VIEWPOINT` line's seven numbers.
    pub fn pcd_words(&self) -> String {
        let [tx, ty, tz] = self.position;
        let [qw, qx, qy, qz] = self.orientation;
        format!("{tx} {ty} {tz} {qw} {qx} {qy} {qz}")
    }

    /// The pose after the cloud is turned by the rotation matrix `r`
    /// (rows) about `about` (the cloud's origin): the position turned, and
    /// the orientation `r · q`.
    pub fn turned(&self, r: [[f64; 3]; 3], about: [f64; 3]) -> Self {
        use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};
        let m = Matrix3::from_fn(|i, k| r[i][k]);
        let o = Vector3::from(about);
        let p = m * (Vector3::from(self.position) - o) + o;
        let turn = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
        let [w, x, y, z] = self.orientation;
        let q = turn.quaternion() * Quaternion::new(w, x, y, z);
        Viewpoint {
            position: [p.x, p.y, p.z],
            orientation: [q.w, q.i, q.j, q.k],
        }
    }
}

/// The CRS a LAS header states (GeoTIFF keys or WKT).
pub(crate) fn las_crs(h: &las::Header) -> Crs {
    let mut crs = Crs::default();
    if let Some(bytes) = h.get_wkt_crs_bytes() {
        let text = String::from_utf8_lossy(bytes)
            .trim_end_matches('\0')
            .to_string();
        (crs.unit, crs.vertical) = Unit::from_wkt_xyz(&text);
        crs.wkt = Some(text);
    }
    if let Ok(Some(keys)) = h.get_geotiff_crs() {
        let key = |id: u16| {
            keys.entries
                .iter()
                .find(|e| e.id == id)
                .and_then(|e| match e.data {
                    las::crs::GeoTiffData::U16(v) => Some(v),
                    _ => None,
                })
        };
        let projected = key(PROJECTED_CS_TYPE).filter(|&c| c != USER_DEFINED);
        let geographic = key(GEOGRAPHIC_TYPE).filter(|&c| c != USER_DEFINED);
        crs.epsg = projected.or(geographic).map(u32::from);
        let unit = match key(GT_MODEL_TYPE) {
            Some(MODEL_GEOGRAPHIC) => Unit::Degree,
            _ if projected.is_none() && geographic.is_some() => Unit::Degree,
            _ => key(PROJ_LINEAR_UNITS)
                .or(key(GEOG_ANGULAR_UNITS).filter(|_| projected.is_none()))
                .map_or(Unit::Unknown, Unit::from_epsg),
        };
        if crs.unit == Unit::Unknown {
            crs.unit = unit;
        }
        if crs.vertical == Unit::Unknown {
            crs.vertical = key(VERTICAL_UNITS).map_or(Unit::Unknown, Unit::from_epsg);
        }
        // A projected EPSG code without a unit key: UTM zones are metres.
        if crs.unit == Unit::Unknown && projected.is_some_and(is_utm) {
            crs.unit = Unit::Metre;
        }
    }
    crs
}

/// Whether an EPSG code is a UTM zone of WGS 84 (326xx, 327xx) or NAD83
/// (269xx), whose unit is the metre.
fn is_utm(code: u16) -> bool {
    matches!(code, 32601..=32660 | 32701..=32760 | 26901..=26923)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_come_from_the_wkt_axes_not_the_base_crs() {
        let utm = r#"PROJCS["NAD83 / UTM zone 10N",GEOGCS["NAD83",UNIT["degree",0.0174532925199433]],UNIT["metre",1]]"#;
        assert_eq!(Unit::from_wkt(utm), Unit::Metre);
        let spcs = r#"PROJCS["NAD83(HARN) / Oregon GIC Lambert (ft)",GEOGCS["NAD83(HARN)",UNIT["degree",0.01745]],UNIT["foot",0.3048]]"#;
        assert_eq!(Unit::from_wkt(spcs), Unit::Foot);
        let us = r#"PROJCS["NAD83 / Texas Central (ftUS)",GEOGCS["NAD83"],UNIT["US survey foot",0.304800609601219]]"#;
        assert_eq!(Unit::from_wkt(us), Unit::UsSurveyFoot);
        assert_eq!(
            Unit::from_wkt(r#"GEOGCS["WGS 84",UNIT["degree",0.01745]]"#),
            Unit::Degree
        );
        assert!((Unit::UsSurveyFoot.metres().unwrap() - 0.304_800_609_6).abs() < 1e-10);
    }

    #[test]
    fn a_viewpoint_turns_with_the_cloud() {
        // A quarter turn about z: x goes to y.
        let r = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let vp = Viewpoint {
            position: [12.0, 5.0, 3.0],
            orientation: [1.0, 0.0, 0.0, 0.0],
        };
        let t = vp.turned(r, [10.0, 5.0, 0.0]);
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!(close(&t.position, &[10.0, 7.0, 3.0]), "{t:?}");
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!(close(&t.orientation, &[h, 0.0, 0.0, h]), "{t:?}");
        // Turned back by the transpose: where it was.
        let back = t.turned(
            [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            [10.0, 5.0, 0.0],
        );
        assert!(close(&back.position, &vp.position) && close(&back.orientation, &vp.orientation));
        assert_eq!(
            Viewpoint::from_pcd([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
            None
        );
    }

    #[test]
    fn a_compound_crs_gives_its_horizontal_and_vertical_units() {
        // PDAL's autzen-bmx-2010.las, shortened: metres, and z in US feet.
        let wkt = r#"COMPD_CS["NAD83 / Oregon LCC (m) + NAVD88 height (ftUS)",PROJCS["NAD83 / Oregon LCC (m)",GEOGCS["NAD83",UNIT["degree",0.0174532925199433]],PROJECTION["Lambert_Conformal_Conic_2SP"],UNIT["metre",1],AXIS["Easting",EAST]],VERT_CS["NAVD88 height (ftUS)",VERT_DATUM["North American Vertical Datum 1988",2005],UNIT["US survey foot",0.304800609601219],AXIS["Gravity-related height",UP]]]"#;
        assert_eq!(Unit::from_wkt_xyz(wkt), (Unit::Metre, Unit::UsSurveyFoot));
        let crs = Crs {
            epsg: None,
            wkt: Some(wkt.into()),
            unit: Unit::Metre,
            vertical: Unit::UsSurveyFoot,
        };
        assert_eq!(crs.to_string(), "WKT (metre, z in US survey foot)");
        assert_eq!(crs.z_unit(), Unit::UsSurveyFoot);
        // Not compound: z in the horizontal unit.
        let utm = r#"PROJCS["UTM",GEOGCS["NAD83",UNIT["degree",0.01745]],UNIT["metre",1]]"#;
        assert_eq!(Unit::from_wkt_xyz(utm), (Unit::Metre, Unit::Unknown));
    }
}
