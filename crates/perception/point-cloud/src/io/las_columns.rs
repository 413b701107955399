//! A LAS point's attributes as the cloud's columns, named as PDAL names
//! LAS dimensions, and back into LAS points on writing.
//!
//! Every point format gives `Intensity`, `ReturnNumber`,
//! `NumberOfReturns`, `ScanDirectionFlag`, `EdgeOfFlightLine`,
//! `Classification`, `Synthetic`, `KeyPoint`, `Withheld`, `Overlap`,
//! `ScanAngleRank` (degrees), `UserData` and `PointSourceId`; formats 6–10
//! add `ScanChannel`; then `GpsTime`, `Red`/`Green`/`Blue`, `Infrared` and
//! `ExtraBytes` (the record's extra bytes, byte for byte) where the format
//! has them. Waveform packets (formats 4, 5, 9, 10) are not carried: such
//! a file reads, and writing it back as LAS is refused by name.

use crate::attributes::{Attributes, Values};

/// The columns of a LAS read, filled a point at a time.
#[derive(Debug, Default)]
pub(crate) struct LasColumns {
    intensity: Vec<u16>,
    return_number: Vec<u8>,
    number_of_returns: Vec<u8>,
    scan_direction: Vec<u8>,
    edge: Vec<u8>,
    classification: Vec<u8>,
    synthetic: Vec<u8>,
    key_point: Vec<u8>,
    withheld: Vec<u8>,
    overlap: Vec<u8>,
    scan_angle: Vec<f32>,
    user_data: Vec<u8>,
    point_source_id: Vec<u16>,
    channel: Option<Vec<u8>>,
    gps_time: Option<Vec<f64>>,
    rgb: Option<[Vec<u16>; 3]>,
    nir: Option<Vec<u16>>,
    extra: Option<(usize, Vec<u8>)>,
}

fn flag(b: bool) -> u8 {
    u8::from(b)
}

impl LasColumns {
    /// Empty columns for the point format `f`.
    pub(crate) fn for_format(f: &las::point::Format) -> Self {
        Self {
            channel: f.is_extended.then(Vec::new),
            gps_time: f.has_gps_time.then(Vec::new),
            rgb: f.has_color.then(Default::default),
            nir: f.has_nir.then(Vec::new),
            extra: (f.extra_bytes > 0).then(|| (usize::from(f.extra_bytes), Vec::new())),
            ..Self::default()
        }
    }

    /// Appends the attributes of `p`.
    pub(crate) fn push(&mut self, p: &las::Point) {
        self.intensity.push(p.intensity);
        self.return_number.push(p.return_number);
        self.number_of_returns.push(p.number_of_returns);
        self.scan_direction.push(flag(
            p.scan_direction == las::point::ScanDirection::LeftToRight,
        ));
        self.edge.push(flag(p.is_edge_of_flight_line));
        self.classification.push(u8::from(p.classification));
        self.synthetic.push(flag(p.is_synthetic));
        self.key_point.push(flag(p.is_key_point));
        self.withheld.push(flag(p.is_withheld));
        self.overlap.push(flag(p.is_overlap));
        self.scan_angle.push(p.scan_angle);
        self.user_data.push(p.user_data);
        self.point_source_id.push(p.point_source_id);
        if let Some(c) = &mut self.channel {
            c.push(p.scanner_channel);
        }
        if let Some(t) = &mut self.gps_time {
            t.push(p.gps_time.unwrap_or(0.0));
        }
        if let Some([r, g, b]) = &mut self.rgb {
            let c = p.color.unwrap_or_default();
            r.push(c.red);
            g.push(c.green);
            b.push(c.blue);
        }
        if let Some(n) = &mut self.nir {
            n.push(p.nir.unwrap_or(0));
        }
        if let Some((w, data)) = &mut self.extra {
            let mut row = p.extra_bytes.clone();
            row.resize(*w, 0);
            data.extend_from_slice(&row);
        }
    }

    /// The columns, named as PDAL names them.
    pub(crate) fn into_attributes(self) -> Attributes {
        let mut a = Attributes::new();
        a.insert("Intensity", Values::U16(self.intensity));
        a.insert("ReturnNumber", Values::U8(self.return_number));
        a.insert("NumberOfReturns", Values::U8(self.number_of_returns));
        a.insert("ScanDirectionFlag", Values::U8(self.scan_direction));
        a.insert("EdgeOfFlightLine", Values::U8(self.edge));
        a.insert("Classification", Values::U8(self.classification));
        a.insert("Synthetic", Values::U8(self.synthetic));
        a.insert("KeyPoint", Values::U8(self.key_point));
        a.insert("Withheld", Values::U8(self.withheld));
        a.insert("Overlap", Values::U8(self.overlap));
        a.insert("ScanAngleRank", Values::F32(self.scan_angle));
        a.insert("UserData", Values::U8(self.user_data));
        a.insert("PointSourceId", Values::U16(self.point_source_id));
        if let Some(c) = self.channel {
            a.insert("ScanChannel", Values::U8(c));
        }
        if let Some(t) = self.gps_time {
            a.insert("GpsTime", Values::F64(t));
        }
        if let Some([r, g, b]) = self.rgb {
            a.insert("Red", Values::U16(r));
            a.insert("Green", Values::U16(g));
            a.insert("Blue", Values::U16(b));
        }
        if let Some(n) = self.nir {
            a.insert("Infrared", Values::U16(n));
        }
        if let Some((width, data)) = self.extra {
            a.insert("ExtraBytes", Values::Bytes { width, data });
        }
        a
    }
}

/// The columns a LAS point has fields for, in [`LasRows`]' order.
const FIELDS: [&str; 19] = [
    "Intensity",
    "ReturnNumber",
    "NumberOfReturns",
    "ScanDirectionFlag",
    "EdgeOfFlightLine",
    "Classification",
    "Synthetic",
    "KeyPoint",
    "Withheld",
    "Overlap",
    "ScanAngleRank",
    "UserData",
    "PointSourceId",
    "ScanChannel",
    "GpsTime",
    "Red",
    "Green",
    "Blue",
    "Infrared",
];

/// The columns of `attrs` a LAS point has no field for.
pub(crate) fn unwritable(attrs: &Attributes) -> Vec<&str> {
    attrs
        .columns()
        .iter()
        .map(|c| c.name.as_str())
        .filter(|n| !FIELDS.contains(n) && *n != "ExtraBytes")
        .collect()
}

/// Reads a cloud's columns back into LAS points: the columns looked up
/// once by name, then a row at a time; a field with no column is zero
/// (return number and count 1).
pub(crate) struct LasRows<'a> {
    cols: [Option<&'a Values>; FIELDS.len()],
    extra: Option<(usize, &'a [u8])>,
    format: las::point::Format,
}

impl<'a> LasRows<'a> {
    /// Rows of `attrs` as points of `format`.
    pub(crate) fn new(attrs: &'a Attributes, format: las::point::Format) -> Self {
        let extra = match attrs.get("ExtraBytes") {
            Some(Values::Bytes { width, data }) => Some((*width, data.as_slice())),
            _ => None,
        };
        Self {
            cols: FIELDS.map(|n| attrs.get(n)),
            extra,
            format,
        }
    }

    fn get(&self, k: usize, i: usize) -> f64 {
        self.cols[k].map_or(0.0, |v| v.f64_at(i))
    }

    /// Row `i` at `(x, y, z)` as a point of the format.
    pub(crate) fn point(&self, i: usize, [x, y, z]: [f64; 3]) -> las::Point {
        let b = |k: usize| self.get(k, i) as u8;
        let w = |k: usize| self.get(k, i) as u16;
        let f = &self.format;
        let (return_number, number_of_returns) = match self.cols[1] {
            Some(_) => (b(1), b(2)),
            None => (1, 1),
        };
        let mut extra_bytes = match self.extra {
            Some((width, data)) => data[i * width..(i + 1) * width].to_vec(),
            None => Vec::new(),
        };
        extra_bytes.resize(usize::from(f.extra_bytes), 0);
        las::Point {
            x,
            y,
            z,
            intensity: w(0),
            return_number,
            number_of_returns,
            scan_direction: if b(3) != 0 {
                las::point::ScanDirection::LeftToRight
            } else {
                las::point::ScanDirection::RightToLeft
            },
            is_edge_of_flight_line: b(4) != 0,
            classification: las::point::Classification::new(b(5))
                .unwrap_or(las::point::Classification::CreatedNeverClassified),
            is_synthetic: b(6) != 0,
            is_key_point: b(7) != 0,
            is_withheld: b(8) != 0,
            is_overlap: b(9) != 0,
            scan_angle: self.get(10, i) as f32,
            user_data: b(11),
            point_source_id: w(12),
            scanner_channel: if f.is_extended { b(13) } else { 0 },
            gps_time: f.has_gps_time.then(|| self.get(14, i)),
            color: f.has_color.then(|| las::Color {
                red: w(15),
                green: w(16),
                blue: w(17),
            }),
            waveform: None,
            nir: f.has_nir.then(|| w(18)),
            extra_bytes,
        }
    }
}

/// The LAS point format that holds `attrs`' columns: `base` (0 for LAS
/// 1.2, 6 for 1.4) raised to one with GPS time, colour or infrared where a
/// column needs it.
pub(crate) fn format_for(attrs: &Attributes, extended: bool) -> u8 {
    let has = |n: &str| attrs.get(n).is_some();
    let colour = has("Red") || has("Green") || has("Blue");
    let time = has("GpsTime");
    if extended {
        match (has("Infrared"), colour) {
            (true, _) => 8,
            (false, true) => 7,
            _ => 6,
        }
    } else {
        match (time, colour) {
            (true, true) => 3,
            (false, true) => 2,
            (true, false) => 1,
            _ => 0,
        }
    }
}
