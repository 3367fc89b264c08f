use super::cell::fast_decimal;
use super::*;
use crate::planning::examples::{supply_vessel, surveyor_rov};

fn opts(required: &[&str]) -> ParseOptions {
    ParseOptions::new("file", required.iter().map(|s| s.to_string()).collect())
}

fn parse(csv: &str, required: &[&str]) -> Result<ParsedLog, LogError> {
    parse_log(csv.as_bytes(), &opts(required))
}

fn err(csv: &str, required: &[&str]) -> LogError {
    match parse(csv, required) {
        Ok(p) => panic!("expected an error, parsed {} rows", p.rows),
        Err(e) => e,
    }
}

/// (kind, line, column) of an error.
fn at(e: &LogError) -> (LogErrorKind, Option<u64>, Option<&str>) {
    (e.kind, e.line, e.column.as_deref())
}

#[test]
fn parses_columns_in_any_order_and_keeps_numeric_unknowns() {
    let csv =
        "u, t ,psi,depth_raw,mode\n0.5,0.0,0.1,12,AUTO\n0.6,0.1,0.2,13,AUTO\n0.7,0.2,0.3,14,MAN\n";
    let p = parse(csv, &["t", "u", "psi"]).unwrap();
    assert_eq!(p.rows, 3);
    assert_eq!(p.table.t, [0.0, 0.1, 0.2]);
    assert_eq!(p.table.names, ["u", "psi", "depth_raw"]);
    assert_eq!(p.table.column("depth_raw"), Some(&[12.0, 13.0, 14.0][..]));
    assert_eq!(p.ignored_columns, ["mode"]);
    assert_eq!(p.warnings.len(), 1);
    assert_eq!(p.warnings[0].column.as_deref(), Some("mode"));
    assert_eq!(
        p.warnings[0].message,
        "mode is ignored: line 2: 'AUTO' is not a number"
    );
    assert!(p.gaps.is_empty());
}

#[test]
fn unknown_columns_with_gaps_nan_or_no_name_are_ignored() {
    let csv = "t,u,aux,flag,\n0,1,,nan,\n1,2,3,1,\n2,3,4,0,\n";
    let p = parse(csv, &["u"]).unwrap();
    assert_eq!(p.table.names, ["u"]);
    assert_eq!(p.ignored_columns, ["aux", "flag", "(column 5, unnamed)"]);
    assert_eq!(
        p.warnings[1].message,
        "flag is ignored: line 2: 'nan' is not a finite number (NaN and infinity are not allowed)"
    );
}

#[test]
fn bom_crlf_quotes_spaces_and_blank_lines_are_accepted() {
    let csv = "\u{feff}t,u\r\n0.0, 1.5 \r\n\r\n\"0.1\",2\r\n  \r\n0.2,3e0\r\n\r\n\n";
    let p = parse(csv, &["t", "u"]).unwrap();
    assert_eq!(p.rows, 3);
    assert_eq!(p.table.names, ["u"]);
    assert_eq!(p.table.t, [0.0, 0.1, 0.2]);
    assert_eq!(p.table.data[0], [1.5, 2.0, 3.0]);
}

#[test]
fn line_numbers_count_blank_lines_crlf_and_a_missing_final_newline() {
    // Header after two blank lines; data with blank lines between.
    let e = err("\n\nt,u\n0,1\n\n\n1,x\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(7), Some("u")));
    let e = err("t,u\r\n0,1\r\n\r\n1,2\r\n2,x\r\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(5), Some("u")));
    let e = err("t,u\n0,1\n1,2\n\n2,x", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(5), Some("u")));
    let e = err("t,u\r\n0,1\r\n1,x", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("u")));
    let e = err("\u{feff}t;u\n", &["u"]);
    assert_eq!(e.line, Some(1));
}

#[test]
fn empty_file_and_too_few_rows() {
    for csv in ["", "\n\n", " \r\n\r\n"] {
        let e = err(csv, &["u"]);
        assert_eq!(at(&e), (LogErrorKind::Empty, None, None), "{csv:?}");
    }
    let e = err("t,u\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::TooFewRows, None, None));
    assert_eq!(
        e.to_string(),
        "file: the log has 0 data rows; at least 2 are needed"
    );
    let e = err("t,u\n0,1\n\n", &["u"]);
    assert_eq!(e.kind, LogErrorKind::TooFewRows);
    assert_eq!(e.message, "the log has 1 data row; at least 2 are needed");
}

#[test]
fn wrong_delimiter_is_named() {
    let e = err("t;u;psi\n0;1;2\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::WrongDelimiter, Some(1), None));
    assert_eq!(
        e.to_string(),
        "file, line 1: the header uses ';' — the format is comma-separated"
    );
    assert!(err("t\tu\n0\t1\n", &["u"]).message.contains("uses tabs"));
    assert!(err("t|u\n0|1\n", &["u"]).message.contains("uses '|'"));
    // A lone column without separators is a missing-columns error.
    assert_eq!(err("t\n0\n1\n", &["u"]).kind, LogErrorKind::MissingColumns);
}

/// A reader giving `chunk` bytes at a time (chunk boundaries anywhere).
struct Chunked<'a>(&'a [u8], usize);

impl Read for Chunked<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.1.min(buf.len()).min(self.0.len());
        buf[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        Ok(n)
    }
}

#[test]
fn bare_cr_line_ends_read_like_lf_at_any_chunk_boundary() {
    let lf = parse("t,u\n0,1\n0.1,2\n0.2,3\n", &["u"]).unwrap();
    for csv in [
        "t,u\r0,1\r0.1,2\r0.2,3\r",
        "t,u\r\n0,1\r\n0.1,2\r\n0.2,3\r\n",
        "t,u\r0,1\r\n0.1,2\n0.2,3",
    ] {
        for chunk in [1, 2, 3, 7, 1 << 16] {
            let p = parse_log(Chunked(csv.as_bytes(), chunk), &opts(&["u"]))
                .unwrap_or_else(|e| panic!("{csv:?} by {chunk}: {e}"));
            assert_eq!(p.table, lf.table, "{csv:?} by {chunk}");
        }
    }
    // Line numbers count CR line ends.
    let e = err("t,u\r0,1\r0.1,x\r0.2,3\r", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("u")));
    // The old report: the whole file as one header of numbers.
    let old_mac = "t,u,v\r-35496.16,1,2\r-35496.06,1,2\r-35495.96,1,2\r";
    let p = parse(old_mac, &["u"]).unwrap();
    assert_eq!(p.rows, 3);
}

#[test]
fn a_wide_header_is_refused_naming_the_limit_and_read_in_linear_time() {
    let n = 100_000;
    let header: Vec<String> = (0..n)
        .map(|i| if i == 0 { "t".into() } else { format!("c{i}") })
        .collect();
    let row = vec!["1"; n].join(",");
    let csv = format!("{}\n{row}\n{}\n", header.join(","), vec!["2"; n].join(","));
    let e = err(&csv, &[]);
    assert_eq!(e.kind, LogErrorKind::TooLarge);
    assert_eq!(
        e.message,
        "the header has 100000 columns, more than the limit of 10000"
    );
    // Allowed that wide, it reads in well under a second (quadratic
    // duplicate detection took 8 s).
    let wide = ParseOptions {
        max_columns: 200_000,
        ..opts(&[])
    };
    let started = std::time::Instant::now();
    let p = parse_log(csv.as_bytes(), &wide).unwrap();
    assert_eq!(p.table.names.len(), n - 1);
    assert!(
        started.elapsed().as_secs_f64() < 3.0,
        "{:?}",
        started.elapsed()
    );
    // A duplicate at the far end is still found.
    let dup = format!("{},c1\n", header.join(","));
    let started = std::time::Instant::now();
    let e = parse_log(dup.as_bytes(), &wide).unwrap_err();
    assert!(started.elapsed().as_secs_f64() < 3.0);
    assert_eq!(
        e.message,
        "column c1 appears twice in the header (columns 2 and 100001)"
    );
}

#[test]
fn ignored_column_warnings_are_bounded() {
    let names: Vec<String> = (0..50).map(|i| format!("note{i}")).collect();
    let cells = vec!["x"; 50].join(",");
    let csv = format!("t,u,{}\n0,1,{cells}\n0.1,2,{cells}\n", names.join(","));
    let p = parse(&csv, &["u"]).unwrap();
    assert_eq!(p.ignored_columns.len(), 50);
    let ignored: Vec<&LogWarning> = p
        .warnings
        .iter()
        .filter(|w| w.message.contains("ignored"))
        .collect();
    assert_eq!(ignored.len(), MAX_COLUMN_WARNINGS + 1);
    assert_eq!(
        ignored[MAX_COLUMN_WARNINGS].message,
        "… and 30 more columns are ignored (unnamed or not fully numeric; all are listed in the ignored columns)"
    );
}

#[test]
fn control_characters_and_long_numbers_are_not_echoed_raw() {
    let e = err("t,u\n0,1\n0.1,\u{1b}[31mred\n", &["u"]);
    assert_eq!(e.message, "'\\u{1b}[31mred' is not a number");
    let e = err("t,u\n1e300,1\n1e299,2\n", &["u"]);
    assert_eq!(
        e.message,
        "t = 1e299 is not after the previous 1e300 (time must strictly increase)"
    );
    let p = parse("t,u,a\u{7}b\n0,1,x\n0.1,2,y\n", &["u"]).unwrap();
    assert_eq!(p.ignored_columns, ["a\\u{7}b"]);
}

#[test]
fn duplicate_column_names_line_and_column() {
    let e = err("t,u,v, u\n0,1,2,3\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::DuplicateColumn, Some(1), Some("u")));
    assert_eq!(
        e.message,
        "column u appears twice in the header (columns 2 and 4)"
    );
}

#[test]
fn missing_columns_are_all_listed_with_who_needs_them() {
    let v = surveyor_rov();
    let header = "t,tau_X,tau_Y,tau_Z,tau_K,tau_M,tau_N,v,w,p,q,R,x,y,z,phi,theta\n";
    let e = parse_log(
        format!("{header}0{}\n", ",0".repeat(16)).as_bytes(),
        &ParseOptions::for_vessel(&v, LogRole::Single, None),
    )
    .unwrap_err();
    assert_eq!(at(&e), (LogErrorKind::MissingColumns, Some(1), None));
    assert_eq!(
        e.to_string(),
        "file, line 1: columns u, r, psi are missing; the header has 'R' for r (names are \
         case-sensitive) (the 6-DOF ROV 'Surveyor ROV' needs t, tau_X, tau_Y, tau_Z, tau_K, \
         tau_M, tau_N, u, v, w, p, q, r, x, y, z, phi, theta, psi)"
    );
    let e = parse_log(
        "t,thr_1,u\n0,0,0\n".as_bytes(),
        &ParseOptions::for_vessel(&supply_vessel(), LogRole::Control, None),
    )
    .unwrap_err();
    assert_eq!(e.file, "control");
    assert!(
        e.message
            .starts_with("columns thr_2, thr_3, thr_4, thr_5, thr_6 are missing")
    );
    // t is required even when not listed.
    let e = err("u,v\n1,2\n", &["u"]);
    assert!(
        e.message
            .starts_with("column t is missing (this log needs t, u)"),
        "{e}"
    );
}

#[test]
fn ragged_rows_name_line_and_first_missing_column() {
    let e = err("t,u,psi\n0,1,2\n1,2\n", &["u", "psi"]);
    assert_eq!(at(&e), (LogErrorKind::RaggedRow, Some(3), Some("psi")));
    assert_eq!(e.message, "the row has 2 fields, the header has 3 columns");
    let e = err("t,u\n0,1\n1,2\n2,3,4\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::RaggedRow, Some(4), None));
}

#[test]
fn text_and_empty_cells_in_required_columns() {
    let mut csv = String::from("t,tau_X,tau_K\n");
    for k in 0..1831 {
        csv.push_str(&format!("{k},1,2\n"));
    }
    csv.push_str("1831,1,abc\n");
    let e = parse_log(
        csv.as_bytes(),
        &ParseOptions::new("control", vec!["tau_K".into()]),
    )
    .unwrap_err();
    assert_eq!(
        at(&e),
        (LogErrorKind::NotNumeric, Some(1833), Some("tau_K"))
    );
    assert_eq!(
        e.to_string(),
        "control, line 1833, column tau_K: 'abc' is not a number"
    );

    let e = err("t,u,v\n0,1,2\n1, ,2\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("u")));
    assert_eq!(e.message, "the cell is empty; every row needs a value");
    let e = err("t,u\n0,1\n,2\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("t")));
    let e = err("t,u\n0,1\n1,1.2.3\n", &["u"]);
    assert_eq!(e.message, "'1.2.3' is not a number");
}

#[test]
fn nan_infinity_and_overflow_are_non_finite() {
    for (cell, shown) in [
        ("NaN", "'NaN'"),
        ("nan", "'nan'"),
        ("inf", "'inf'"),
        ("-Infinity", "'-Infinity'"),
        ("1e400", "'1e400'"),
    ] {
        let e = err(&format!("t,u\n0,1\n1,2\n2,{cell}\n"), &["u"]);
        assert_eq!(
            at(&e),
            (LogErrorKind::NonFinite, Some(4), Some("u")),
            "{cell}"
        );
        assert!(
            e.message
                .starts_with(&format!("{shown} is not a finite number"))
        );
    }
    let e = err("t,u\n0,1\nNAN,2\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::NonFinite, Some(3), Some("t")));
}

#[test]
fn time_must_strictly_increase() {
    let mut csv = String::from("t,u\n");
    for k in 0..9 {
        csv.push_str(&format!("{:.1},0\n", 2.4 + 0.1 * k as f64));
    }
    assert_eq!(parse(&csv, &["u"]).unwrap().rows, 9);
    let e = err(&format!("{csv}3.1,0\n"), &["u"]);
    assert_eq!(
        at(&e),
        (LogErrorKind::NonMonotonicTime, Some(11), Some("t"))
    );
    let e = err("t,u\n0,1\n0.5,1\n0.5,2\n", &["u"]);
    assert_eq!(at(&e), (LogErrorKind::DuplicateTime, Some(4), Some("t")));
    assert_eq!(
        e.message,
        "t = 0.5 repeats the previous time stamp (time must strictly increase)"
    );
    let e = err("t,u\n0,1\n3.3,1\n3.2,2\n", &["u"]);
    assert_eq!(
        e.to_string(),
        "file, line 4, column t: t = 3.2 is not after the previous 3.3 (time must strictly increase)"
    );
}

#[test]
fn fast_decimal_path_agrees_with_str_parse() {
    let mut cases: Vec<String> = [
        "0",
        "-0",
        "+1",
        "1.",
        ".5",
        "-.5",
        "0.1",
        "0.3",
        "123456.789",
        "-0.000001",
        "9007199254740992",
        "9007199254740993",
        "0.12345678901234567",
        "1.0000000000000000000001",
        "12345678901234567890",
        "1e5",
        ".",
        "-",
        "",
        "1.2.3",
        "--1",
        "0x10",
        "1_0",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    // Deterministic pseudo-random decimals of every length.
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    for _ in 0..20_000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let digits = format!("{}", state % 10u64.pow((state % 17) as u32 + 1));
        let cut = (state >> 40) as usize % (digits.len() + 1);
        let sign = if state & 1 == 1 { "-" } else { "" };
        cases.push(format!("{sign}{}.{}", &digits[..cut], &digits[cut..]));
    }
    for c in &cases {
        let fast = fast_decimal(c.as_bytes());
        let slow: Option<f64> = c.parse().ok();
        if let Some(f) = fast {
            assert_eq!(Some(f.to_bits()), slow.map(f64::to_bits), "{c}");
        }
    }
    assert!(fast_decimal(b"0.1").is_some() && fast_decimal(b"1e5").is_none());
}

#[test]
fn too_many_rows() {
    let o = ParseOptions {
        max_rows: 3,
        ..opts(&["u"])
    };
    assert_eq!(
        parse_log("t,u\n0,1\n1,1\n2,1\n".as_bytes(), &o)
            .unwrap()
            .rows,
        3
    );
    let e = parse_log("t,u\n0,1\n1,1\n2,1\n\n3,1\n".as_bytes(), &o).unwrap_err();
    assert_eq!(at(&e), (LogErrorKind::TooLarge, Some(6), None));
}

#[test]
fn reader_failure_is_io() {
    struct Failing(usize);
    impl Read for Failing {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.0 == 0 {
                return Err(io::Error::other("disk gone"));
            }
            self.0 = 0;
            let s = b"t,u\n0,1\n";
            buf[..s.len()].copy_from_slice(s);
            Ok(s.len())
        }
    }
    let e = parse_log(Failing(1), &opts(&["u"])).unwrap_err();
    assert_eq!(e.kind, LogErrorKind::Io);
    assert!(e.message.contains("disk gone"));
}

#[test]
fn heading_in_degrees_warns_and_radians_do_not() {
    let mut deg = String::from("t,u,psi\n");
    let mut rad = deg.clone();
    for k in 0..200 {
        let heading = (350.0 + 0.3 * k as f64) % 360.0;
        deg.push_str(&format!(
            "{},{},{heading}\n",
            0.1 * k as f64,
            1.0 + 0.01 * k as f64
        ));
        rad.push_str(&format!(
            "{},{},{}\n",
            0.1 * k as f64,
            1.0 + 0.01 * k as f64,
            heading.to_radians()
        ));
    }
    let p = parse(&deg, &["u", "psi"]).unwrap();
    assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
    assert_eq!(p.warnings[0].column.as_deref(), Some("psi"));
    assert!(
        p.warnings[0]
            .message
            .starts_with("psi looks like degrees (max 359.9")
    );
    let p = parse(&rad, &["u", "psi"]).unwrap();
    assert!(p.warnings.is_empty(), "{:?}", p.warnings);
}

#[test]
fn gaps_are_reported_with_missing_counts() {
    // 10 Hz; after t = 1.0 three samples are missing, after 3.0 twenty.
    let mut t: Vec<f64> = (0..=10).map(|k| k as f64 * 0.1).collect();
    t.extend((14..=30).map(|k| k as f64 * 0.1));
    t.extend((51..=60).map(|k| k as f64 * 0.1));
    let mut csv = String::from("t,u\n");
    for (k, v) in t.iter().enumerate() {
        csv.push_str(&format!("{v},{}\n", k % 7));
    }
    let p = parse(&csv, &["u"]).unwrap();
    let got: Vec<(usize, bool)> = p
        .gaps
        .iter()
        .map(|g| (g.missing_samples, g.bridged))
        .collect();
    assert_eq!(got, [(3, true), (20, false)]);
    assert_eq!(
        (p.gaps[0].start_t, p.gaps[0].end_t),
        (1.0, 1.4000000000000001)
    );
    assert_eq!(p.gaps[1].start_t, 3.0);
}
