//! Clock alignment of two logs read from arbitrary bytes (a control log and
//! a navigation log split at the first `#` line, the shared channel `z`, a
//! rate from the first byte): an aligned record or an `AlignError`, never a
//! panic, and an offset that is finite when one is reported.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seatrial_core::alignment::{OffsetOptions, align_logs};
use seatrial_core::logs::{ParseOptions, parse_log};

fuzz_target!(|data: &[u8]| {
    let Some((&rate, rest)) = data.split_first() else {
        return;
    };
    let text = String::from_utf8_lossy(rest);
    let Some((control, nav)) = text.split_once("\n#\n") else {
        return;
    };
    let read = |s: &str, file: &str| {
        let mut opts = ParseOptions::new(file, vec!["z".to_string()]);
        opts.max_rows = 5_000;
        opts.max_columns = 16;
        parse_log(s.as_bytes(), &opts).ok()
    };
    let (Some(control), Some(nav)) = (read(control, "control"), read(nav, "nav")) else {
        return;
    };
    let rate_hz = (rate > 0).then(|| f64::from(rate) / 4.0);
    if let Ok((record, report)) =
        align_logs(&control.table, &nav.table, "z", rate_hz, &OffsetOptions::default())
    {
        assert!(report.offset_used_s.is_finite());
        assert!(record.sample_rate_hz.is_finite() && record.sample_rate_hz > 0.0);
        let n = record.data.first().map_or(0, Vec::len);
        assert!(record.data.iter().all(|c| c.len() == n));
        assert!(record.valid.iter().all(|r| r.end <= n));
    }
});
