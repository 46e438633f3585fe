#![doc = include_str!("../README.md")]

pub mod args;
pub mod brdf;
pub mod export;
pub mod fit;
pub mod maps;
pub mod presets;
pub mod profile;
pub mod render;
pub mod spectrum;

/// Show the libraries' notices (the `log` facade: a table being built, a fallback taken) on stderr
/// as plain lines, at `info` and above unless `RUST_LOG` says otherwise. The binaries call it once.
pub fn init_logging() {
    let _ = env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("info"))
        .format(|buf, record| {
            use std::io::Write as _;
            writeln!(buf, "{}", record.args())
        })
        .try_init();
}

/// An error and its causes on one line, `: `-separated, leaving out a cause whose text the message
/// already shows (many errors print their source themselves, so `{:#}` would repeat it).
#[must_use]
pub fn one_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        let text = text.trim();
        if line.contains(text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(text);
    }
    line.replace('\n', " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn os_error_is_printed_once() {
        let io = std::io::Error::other("no such file (os error 2)");
        let e = ::render::error::RenderError::MissingFile {
            what: "scene",
            path: "x.toml".into(),
            source: io,
        };
        let line = one_line(&anyhow::Error::new(e).context("loading"));
        assert_eq!(line.matches("os error 2").count(), 1, "{line}");
        assert!(line.starts_with("loading: scene file x.toml"), "{line}");
    }
}
