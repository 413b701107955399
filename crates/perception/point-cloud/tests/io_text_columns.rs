//! Text clouds read columns by name (issue 11): a header line picks x, y and
//! z in any case and order, other columns are attributes (issue 46) unless
//! one holds a value that is not a number, which is ignored and counted; missing
//! or repeated axes, decimal commas and mixed separators are refused with
//! the line at fault; headerless files stay positional.

use autoshovel_point_cloud::io::{read_from_bytes, Format};

fn read(text: &str) -> Result<(Vec<[f32; 3]>, usize), String> {
    read_from_bytes(Format::Csv, text.as_bytes())
        .map(|r| (r.cloud.points, r.ignored_columns))
        .map_err(|e| e.to_string())
}

#[test]
fn a_header_picks_the_axes_by_name_in_any_order() {
    let (p, ignored) = read("y,x,z\n1,2,3\n4,5,6\n").unwrap();
    assert_eq!(p, vec![[2.0, 1.0, 3.0], [5.0, 4.0, 6.0]]);
    assert_eq!(ignored, 0);
    let (p, ignored) = read("Intensity;X;Y;Z;Ring\n9;1.5;2.5;3.5;7\n").unwrap();
    assert_eq!(p, vec![[1.5, 2.5, 3.5]]);
    assert_eq!(ignored, 0);
    let (p, _) = read("\"z\" \"x\" \"y\"\n3 1 2\n").unwrap();
    assert_eq!(p, vec![[1.0, 2.0, 3.0]]);
}

#[test]
fn without_a_header_the_first_three_fields_are_xyz() {
    let (p, ignored) = read("# a comment\n1 2 3 99\n4\t5\t6\n").unwrap();
    assert_eq!(p, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    assert_eq!(ignored, 0);
    let (p, _) = read("1, 2, 3\n").unwrap();
    assert_eq!(p, vec![[1.0, 2.0, 3.0]]);
}

#[test]
fn missing_or_repeated_axes_are_refused_naming_the_header() {
    let e = read("a,b,c\n1,2,3\n").unwrap_err();
    assert!(
        e.contains("line 1") && e.contains("\"a,b,c\"") && e.contains("\"x\""),
        "{e}"
    );
    let e = read("x,y,y,z\n1,2,3,4\n").unwrap_err();
    assert!(e.contains("ambiguous") && e.contains("\"y\""), "{e}");
    let e = read("# scan\nx,y\n1,2\n").unwrap_err();
    assert!(e.contains("line 2") && e.contains("\"z\""), "{e}");
}

#[test]
fn decimal_commas_and_mixed_separators_are_refused_not_guessed() {
    let e = read("x;y;z\n1,5;2,5;3,5\n").unwrap_err();
    assert!(e.contains("line 2") && e.contains("decimal comma"), "{e}");
    let e = read("1,5;2,5;3,5\n").unwrap_err();
    assert!(e.contains("line 1") && e.contains("decimal comma"), "{e}");
    let e = read("1,2,3\n4;5;6\n").unwrap_err();
    assert!(e.contains("line 2") && e.contains("not a number"), "{e}");
}

#[test]
fn a_short_row_names_its_line_and_the_columns_needed() {
    let e = read("intensity,x,y,z\n1,2,3\n").unwrap_err();
    assert!(e.contains("line 2") && e.contains("needs 4 fields"), "{e}");
}

#[test]
fn other_header_columns_are_attributes_and_a_column_of_words_is_counted() {
    let r = read_from_bytes(
        Format::Csv,
        b"intensity,x,y,z,ring,label\n9,1,2,3,7,rock\n10,4,5,6,8,ore\n",
    )
    .unwrap();
    let a = &r.cloud.attributes;
    // PDAL's name where it has the dimension, the file's otherwise.
    assert_eq!(
        a.get("Intensity").map(|v| (v.f64_at(0), v.f64_at(1))),
        Some((9.0, 10.0))
    );
    assert_eq!(
        a.get("ring").map(|v| (v.f64_at(0), v.f64_at(1))),
        Some((7.0, 8.0))
    );
    assert!(a.get("label").is_none());
    assert_eq!(r.ignored_columns, 1, "the words' column");
}
