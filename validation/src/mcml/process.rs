//! Running an MCML binary on an `.mci` text and reading back every run's output.

use super::{McmlError, McmlOutput, McmlRun, parse_mco};
use std::path::Path;
use std::process::Command;

/// What one MCML process produced: each run's output, and the CPU time it used.
#[derive(Debug, Clone, PartialEq)]
pub struct McmlProcess {
    /// One output per run of the input, in order.
    pub outputs: Vec<McmlOutput>,
    /// User + system CPU seconds of the MCML process (its rusage as the kernel reports it for
    /// waited-for children in `/proc/self/stat`, 10 ms ticks); `None` off Linux. Only meaningful
    /// when no other child process of ours ends meanwhile.
    pub cpu_seconds: Option<f64>,
}

/// User + system CPU seconds of this process's waited-for children (`cutime` + `cstime`, fields 16
/// and 17 of `/proc/self/stat`, in clock ticks of 1/100 s).
fn children_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name, which is in parentheses and may contain spaces.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(13)?.parse::<f64>().ok()? + f.get(14)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// On-CPU seconds of the calling thread (`/proc/thread-self/schedstat`, ns; Linux), for the
/// one-thread speed comparison with MCML's child-process time; `None` elsewhere.
#[must_use]
pub fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

/// Run `binary` on `mci` (whose runs are `runs`) in the directory `dir` and parse each run's output.
pub fn run_mcml(
    binary: &Path,
    mci: &str,
    runs: &[McmlRun],
    dir: &Path,
) -> Result<McmlProcess, McmlError> {
    let io = |what: &str, e: std::io::Error| McmlError::Output(format!("{what}: {e}"));
    std::fs::write(dir.join("input.mci"), mci).map_err(|e| io("writing input.mci", e))?;
    let before = children_cpu_seconds();
    let out = Command::new(binary)
        .arg("input.mci")
        .current_dir(dir)
        .output()
        .map_err(|e| io(&format!("running {}", binary.display()), e))?;
    let after = children_cpu_seconds();
    if !out.status.success() {
        return Err(McmlError::Output(format!(
            "{} exited with {}: {}",
            binary.display(),
            out.status,
            [&out.stdout, &out.stderr]
                .map(|b| String::from_utf8_lossy(b).trim().to_string())
                .join(" / ")
        )));
    }
    let outputs = runs
        .iter()
        .map(|r| {
            let text = std::fs::read_to_string(dir.join(&r.output))
                .map_err(|e| io(&format!("reading {}", r.output), e))?;
            parse_mco(&text)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(McmlProcess {
        outputs,
        cpu_seconds: before.zip(after).map(|(b, a)| a - b),
    })
}
