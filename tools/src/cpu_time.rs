//! CPU time for the benchmarks: this process's (getrusage, which on a CPU Vulkan device includes
//! the device's own threads) and, on Linux, the whole machine's (/proc/stat), so that a figure
//! disturbed by other work on a shared machine says so.

/// CPU seconds since boot or process start; `None` where the platform does not tell.
#[derive(Clone, Copy, Debug)]
pub struct CpuTimes {
    /// User + system seconds of this process.
    pub process: Option<f64>,
    /// User + nice + system + irq + softirq seconds of every CPU of the machine.
    pub machine_busy: Option<f64>,
    /// Seconds the hypervisor ran something else on this machine's CPUs.
    pub machine_steal: Option<f64>,
}

/// CPU seconds over an interval (`CpuTimes::since`).
#[derive(Clone, Copy, Debug, Default)]
pub struct CpuUse {
    pub process: Option<f64>,
    /// Every other process's: the machine's busy time less this process's.
    pub others: Option<f64>,
    pub steal: Option<f64>,
}

impl CpuTimes {
    pub fn now() -> CpuTimes {
        let machine = machine_seconds();
        CpuTimes {
            process: process_seconds(),
            machine_busy: machine.map(|m| m.0),
            machine_steal: machine.map(|m| m.1),
        }
    }

    pub fn since(self, earlier: CpuTimes) -> CpuUse {
        let delta = |a: Option<f64>, b: Option<f64>| a.zip(b).map(|(a, b)| a - b);
        let process = delta(self.process, earlier.process);
        // /proc/stat counts in clock ticks: a small negative remainder is rounding, not time.
        let others = delta(self.machine_busy, earlier.machine_busy)
            .zip(process)
            .map(|(busy, own)| (busy - own).max(0.0));
        CpuUse {
            process,
            others,
            steal: delta(self.machine_steal, earlier.machine_steal),
        }
    }
}

impl CpuUse {
    /// Adds `other`; a figure unknown in either stays unknown.
    pub fn add(&mut self, other: CpuUse) {
        let sum = |a: Option<f64>, b: Option<f64>| a.zip(b).map(|(a, b)| a + b);
        *self = CpuUse {
            process: sum(self.process, other.process),
            others: sum(self.others, other.others),
            steal: sum(self.steal, other.steal),
        };
    }
}

#[cfg(unix)]
fn process_seconds() -> Option<f64> {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage only writes the struct it is given; RUSAGE_SELF is always valid.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, usage.as_mut_ptr()) } != 0 {
        return None;
    }
    // SAFETY: zero-initialised and filled in by the successful call above.
    let usage = unsafe { usage.assume_init() };
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    Some(seconds(usage.ru_utime) + seconds(usage.ru_stime))
}

#[cfg(not(unix))]
fn process_seconds() -> Option<f64> {
    None
}

/// (busy, steal) seconds of all CPUs from the first line of /proc/stat.
#[cfg(target_os = "linux")]
fn machine_seconds() -> Option<(f64, f64)> {
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    let ticks: Vec<u64> = stat
        .lines()
        .next()?
        .strip_prefix("cpu ")?
        .split_whitespace()
        .map(|v| v.parse().ok())
        .collect::<Option<_>>()?;
    // user nice system idle iowait irq softirq steal (guest time is already in user and nice).
    let [user, nice, system, _idle, _iowait, irq, softirq, steal, ..] = ticks[..] else {
        return None;
    };
    // SAFETY: sysconf only reads a configuration value.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if hz <= 0 {
        return None;
    }
    let seconds = |t: u64| t as f64 / hz as f64;
    Some((
        seconds(user + nice + system + irq + softirq),
        seconds(steal),
    ))
}

#[cfg(not(target_os = "linux"))]
fn machine_seconds() -> Option<(f64, f64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_figure_of_an_interval_is_known_and_not_negative_on_linux() {
        let start = CpuTimes::now();
        let used = CpuTimes::now().since(start);
        assert!(used.process.is_some_and(|s| s >= 0.0));
        #[cfg(target_os = "linux")]
        assert!(
            used.others.is_some_and(|s| s >= 0.0) && used.steal.is_some_and(|s| s >= 0.0),
            "{used:?}"
        );
    }
}
