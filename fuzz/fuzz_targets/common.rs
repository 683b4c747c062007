// Shared by every target (included with `include!`).

/// The memory budget the targets run under (Sylva's `--max-memory`): 1 GiB, so that work
/// Sylva accepts stays under libFuzzer's `-rss_limit_mb=2048` and going over it is a bug
/// in an estimate, not a legal request.
fn set_budget() {
    sylva_core::budget::set_max_memory(1 << 30);
}
