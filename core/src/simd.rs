//! Which vector instructions the kernels use: the widest the CPU has, chosen once at run
//! time, or a narrower one named by `TRACELAB_SIMD` (`sse`, `avx`, `avx512`), so tests and
//! benchmarks run every path this machine supports. A wider level than the CPU has is never
//! used: asking for one gives the widest the CPU has.

use std::sync::OnceLock;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// 4-wide SSE2, every x86-64 CPU (and the portable code elsewhere).
    Sse,
    /// 8-wide AVX.
    Avx,
    /// AVX-512 (F and VL): 16-wide registers and mask registers, for the kernels that have
    /// such a version (a packet's rays two at a time against a leaf); the others run AVX.
    Avx512,
}

impl Level {
    pub fn name(self) -> &'static str {
        match self {
            Level::Sse => "sse",
            Level::Avx => "avx",
            Level::Avx512 => "avx512",
        }
    }
}

/// The widest level the CPU has.
pub fn detected() -> Level {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
    {
        return Level::Avx512;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        return Level::Avx;
    }
    Level::Sse
}

/// The level in use: `detected()`, lowered by `TRACELAB_SIMD` (read once; an unknown or
/// wider value than the CPU has is ignored, with a warning through `log`).
#[inline]
pub fn level() -> Level {
    static LEVEL: OnceLock<Level> = OnceLock::new();
    *LEVEL.get_or_init(|| choose(std::env::var("TRACELAB_SIMD").ok().as_deref(), detected()))
}

fn choose(asked: Option<&str>, cpu: Level) -> Level {
    let wanted = match asked {
        None | Some("") => return cpu,
        Some("sse") => Level::Sse,
        Some("avx") => Level::Avx,
        Some("avx512") => Level::Avx512,
        Some(other) => {
            log::warn!(
                "TRACELAB_SIMD={other:?} is not one of sse, avx, avx512; using {}",
                cpu.name()
            );
            return cpu;
        }
    };
    if wanted > cpu {
        log::warn!(
            "TRACELAB_SIMD={} but this CPU has only {}; using {}",
            wanted.name(),
            cpu.name(),
            cpu.name()
        );
        return cpu;
    }
    wanted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_variable_only_narrows() {
        assert_eq!(choose(None, Level::Avx), Level::Avx);
        assert_eq!(choose(Some("sse"), Level::Avx), Level::Sse);
        assert_eq!(choose(Some("avx"), Level::Sse), Level::Sse);
        assert_eq!(choose(Some("avx512"), Level::Avx), Level::Avx);
        assert_eq!(choose(Some("avx512"), Level::Sse), Level::Sse);
        assert_eq!(choose(Some("avx"), Level::Avx), Level::Avx);
        assert_eq!(choose(None, Level::Avx512), Level::Avx512);
        assert_eq!(choose(Some("avx512"), Level::Avx512), Level::Avx512);
        assert_eq!(choose(Some("avx"), Level::Avx512), Level::Avx);
        assert_eq!(choose(Some("sse"), Level::Avx512), Level::Sse);
    }
}
