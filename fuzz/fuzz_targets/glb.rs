//! The GLB (binary glTF 2.0) reader: `sylva_gltf::import::read_glb`.
//!
//! A custom mutator keeps the GLB framing: half the time it mutates only the JSON chunk and
//! writes the chunk and file lengths back, so that changes to the JSON (a huge
//! `byteOffset`, a new node) reach the reader instead of breaking the chunk layout.
#![no_main]
use libfuzzer_sys::{fuzz_mutator, fuzz_target, fuzzer_mutate};
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let _ = sylva_gltf::import::read_glb(data);
});

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// The JSON chunk and the BIN chunk (empty if none) of a well-framed GLB.
fn chunks(data: &[u8]) -> Option<(Vec<u8>, Vec<u8>)> {
    if u32_at(data, 0)? != 0x4654_6C67 {
        return None;
    }
    let len = u32_at(data, 12)? as usize;
    if u32_at(data, 16)? != 0x4E4F_534A {
        return None;
    }
    let json = data.get(20..20 + len)?.to_vec();
    let at = 20 + len.next_multiple_of(4);
    let bin = match (u32_at(data, at), u32_at(data, at + 4)) {
        (Some(n), Some(0x004E_4942)) => data.get(at + 8..at + 8 + n as usize)?.to_vec(),
        _ => Vec::new(),
    };
    Some((json, bin))
}

fuzz_mutator!(|data: &mut [u8], size: usize, max_size: usize, seed: u32| {
    if seed % 2 == 0 {
        if let Some((mut json, bin)) = chunks(&data[..size]) {
            let room = max_size.saturating_sub(28 + bin.len() + 3);
            if room > 0 {
                let used = json.len().min(room);
                json.resize(room, 0);
                let n = fuzzer_mutate(&mut json, used, room);
                json.truncate(n);
                while json.len() % 4 != 0 {
                    json.push(b' ');
                }
                let mut out = Vec::with_capacity(28 + json.len() + bin.len());
                out.extend_from_slice(&0x4654_6C67u32.to_le_bytes());
                out.extend_from_slice(&2u32.to_le_bytes());
                out.extend_from_slice(&0u32.to_le_bytes());
                out.extend_from_slice(&(json.len() as u32).to_le_bytes());
                out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
                out.extend_from_slice(&json);
                if !bin.is_empty() {
                    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
                    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
                    out.extend_from_slice(&bin);
                }
                let total = out.len() as u32;
                out[8..12].copy_from_slice(&total.to_le_bytes());
                if out.len() <= max_size {
                    data[..out.len()].copy_from_slice(&out);
                    return out.len();
                }
            }
        }
    }
    fuzzer_mutate(data, size, max_size)
});
