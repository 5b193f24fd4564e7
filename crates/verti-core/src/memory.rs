//! How much memory this process may use: a plan or buffer sized by the user's parameters is
//! checked against it before a run, so a run that cannot fit is refused with the figures
//! instead of aborting on a failed allocation hours in (Rust aborts on allocation failure).

/// The bytes this process may use: the smaller of its address-space limit (`ulimit -v`) and
/// the machine's physical memory; `None` where neither can be read (not Linux). Read once per
/// process: systems are built once per trial, and neither figure changes while it runs.
pub fn usable_bytes() -> Option<u64> {
    static USABLE: std::sync::OnceLock<Option<u64>> = std::sync::OnceLock::new();
    *USABLE.get_or_init(read_usable_bytes)
}

fn read_usable_bytes() -> Option<u64> {
    let limit = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|t| address_space_limit(&t));
    let total = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| mem_total(&t));
    match (limit, total) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The soft `Max address space` of `/proc/self/limits`, in bytes (`None`: unlimited).
fn address_space_limit(limits: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// `MemTotal` of `/proc/meminfo`, in bytes.
fn mem_total(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// `bytes` for people: `1.5 GB`, `640 MB`.
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).max(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_meminfo_are_read() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max address space         4096000000           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limits), Some(4_096_000_000));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes     \n";
        assert_eq!(address_space_limit(unlimited), None);
        assert_eq!(
            mem_total("MemTotal:       24684084 kB\n"),
            Some(24684084 * 1024)
        );
        assert_eq!(human(10_485_760_000), "10.5 GB");
        assert_eq!(human(640_000_000), "640 MB");
    }
}
