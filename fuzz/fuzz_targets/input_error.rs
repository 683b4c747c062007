//! Error positions in input text: `InputError::at` (line and column from the first 16
//! bytes) and `InputError::spanned` (a range from the same bytes), over the rest of the
//! input as text.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use sylva::InputError;
include!("common.rs");

fn word(bytes: &[u8]) -> usize {
    let mut b = [0u8; 8];
    b.copy_from_slice(bytes);
    // Small numbers most of the time, any usize sometimes: the top byte picks.
    let v = u64::from_le_bytes(b);
    (if b[7] & 0x80 == 0 { v & 0xffff } else { v }) as usize
}

fuzz_target!(|data: &[u8]| {
    set_budget();
    if data.len() < 16 {
        return;
    }
    let (a, b) = (word(&data[0..8]), word(&data[8..16]));
    let Ok(text) = std::str::from_utf8(&data[16..]) else {
        return;
    };
    let path = Path::new("f");
    let _ = InputError::at(path, text, a, b, String::new());
    let _ = InputError::spanned(path, text, a..b, String::new());
});
