//! The log reader on arbitrary bytes: every input is a parsed table or a
//! `LogError`, never a panic, and a parsed table keeps its promises (as
//! many values per column as rows, increasing finite time stamps).
#![no_main]

use libfuzzer_sys::fuzz_target;
use seatrial_core::logs::{ParseOptions, parse_log};

fuzz_target!(|data: &[u8]| {
    let mut opts = ParseOptions::new("file", vec!["u".to_string()]);
    opts.max_rows = 20_000;
    opts.max_columns = 200;
    if let Ok(log) = parse_log(data, &opts) {
        let t = &log.table.t;
        assert_eq!(t.len(), log.rows);
        assert!(t.iter().all(|x| x.is_finite()));
        assert!(t.windows(2).all(|w| w[1] > w[0]), "time stamps increase");
        assert_eq!(log.table.names.len(), log.table.data.len());
        for (name, column) in log.table.names.iter().zip(&log.table.data) {
            assert_eq!(column.len(), log.rows, "{name}");
        }
    }
});
