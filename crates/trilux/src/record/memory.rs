//! The process's peak resident memory, as the kernel counts it.

/// The peak resident set size in bytes: `VmHWM` of /proc/self/status on
/// Linux (what `/usr/bin/time -v` reports as the maximum resident set),
/// `None` where there is no such file or it has no such line.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    vm_hwm(&status)
}

/// The `VmHWM:  N kB` line of a /proc status text, in bytes.
fn vm_hwm(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let mut words = line["VmHWM:".len()..].split_whitespace();
    let kib: u64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then(|| kib.saturating_mul(1024))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_high_water_mark_line_is_read_in_kibibytes() {
        let status = "Name:\ttrilux\nVmPeak:\t  9000 kB\nVmHWM:\t    1234 kB\nVmRSS:\t  1000 kB\n";
        assert_eq!(vm_hwm(status), Some(1234 * 1024));
        assert_eq!(vm_hwm("VmRSS:\t 1 kB\n"), None);
        assert_eq!(vm_hwm("VmHWM:\t x kB\n"), None);
    }
}
