//! Errors the engine reports instead of panicking: every one names what is wrong and where.

use std::fmt;

/// Invalid input to the engine. Converted to Python's `ValueError` by the bindings.
#[derive(Clone, Debug, PartialEq)]
pub struct EngineError(pub String);

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for EngineError {}

/// `x` to three significant digits, in plain notation between 0.001 and 10^6 and in
/// exponent notation otherwise (`2.5e8`): for numbers in messages, which may be extreme.
pub fn approx(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-3..1e6).contains(&x.abs()) {
        let digits = if x == 0.0 || !x.is_finite() {
            0
        } else {
            (2 - x.abs().log10().floor() as i32).max(0) as usize
        };
        return format!("{x:.digits$}");
    }
    let text = format!("{x:.2e}");
    // `2.50e8` -> `2.5e8`, `1.00e-7` -> `1e-7`
    match text.split_once('e') {
        Some((mantissa, exponent)) if mantissa.contains('.') => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exponent}")
        }
        _ => text,
    }
}

/// Shorthand for building an `Err(EngineError)` from a formatted message.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err($crate::error::EngineError(format!($($arg)*)))
    };
}
pub(crate) use bail;

#[cfg(test)]
mod tests {
    use super::approx;

    #[test]
    fn approx_keeps_three_digits_in_readable_notation() {
        assert_eq!(approx(0.0), "0");
        assert_eq!(approx(2.0e8), "2e8");
        assert_eq!(approx(2.5e8), "2.5e8");
        assert_eq!(approx(123456.0), "123456");
        assert_eq!(approx(0.009000000000000001), "0.00900");
        assert_eq!(approx(1e-200), "1e-200");
        assert_eq!(approx(-1.23456), "-1.23");
        assert_eq!(approx(f64::INFINITY), "inf");
    }
}
