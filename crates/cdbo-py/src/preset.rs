//! `preset=`: the recommended stack by one name (`cdbo race --preset`), read by the library's
//! [`Preset`] for `cdbo.race`, `Study.create` and `RaceEnv`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use cdbo::drive::steering::SteeringLaw;
use cdbo::line::LineKind;
use cdbo::method::{Method, Preset};

use crate::convert::IntoPy;

/// The learner, the steering and the line a race asks for: `preset`'s, or the arguments
/// given, each left out at its default (CDBO, the PI steering, the centre line). Beside a
/// preset, an argument of its stack (`method`, `steering`, `line`, `line_kernels`,
/// `line_start`) is refused naming both: one name never mixes with another setting.
pub struct Stack {
    /// The learner.
    pub method: Method,
    /// The steering.
    pub steering: SteeringLaw,
    /// The line.
    pub line: LineKind,
}

impl Stack {
    /// The stack of `preset` or of the other arguments (the names as Python gives them).
    pub fn of(
        preset: Option<&str>,
        method: Option<&str>,
        steering: Option<&str>,
        line: Option<&str>,
        line_kernels: Option<usize>,
        line_start: Option<&str>,
    ) -> PyResult<Stack> {
        let Some(name) = preset else {
            return Ok(Stack {
                method: method.map_or(Ok(Method::Cdbo), str::parse).py()?,
                steering: steering.map_or(Ok(SteeringLaw::Pi), str::parse).py()?,
                line: line.map_or(Ok(LineKind::Centre), str::parse).py()?,
            });
        };
        let preset: Preset = name.parse().py()?;
        let given = [
            ("method", method.map(str::to_owned)),
            ("steering", steering.map(str::to_owned)),
            ("line", line.map(str::to_owned)),
            ("line_kernels", line_kernels.map(|k| k.to_string())),
            ("line_start", line_start.map(str::to_owned)),
        ];
        if let Some((argument, Some(value))) = given.into_iter().find(|(_, v)| v.is_some()) {
            return Err(PyValueError::new_err(format!(
                "preset={:?} sets method={:?}, steering={:?} and line={:?}: give the preset or \
                 these arguments, not both (got {argument}={value:?})",
                preset.name(),
                preset.method().name(),
                preset.steering().name(),
                preset.line().name(),
            )));
        }
        Ok(Stack {
            method: preset.method(),
            steering: preset.steering(),
            line: preset.line(),
        })
    }
}

/// `(method, steering, line)`: the names of the stack `preset` sets (`"fast-safe"`:
/// `("safe-pattern-search", "tracker", "min-curvature")`), or of the arguments given, each
/// left out at its default (`"cdbo"`, `"pi"`, `"centre"`); an argument of the stack beside
/// the preset raises `ValueError`.
#[pyfunction]
#[pyo3(signature = (preset = None, *, method = None, steering = None, line = None, line_kernels = None, line_start = None))]
pub fn resolve_stack(
    preset: Option<&str>,
    method: Option<&str>,
    steering: Option<&str>,
    line: Option<&str>,
    line_kernels: Option<usize>,
    line_start: Option<&str>,
) -> PyResult<(&'static str, &'static str, &'static str)> {
    let stack = Stack::of(preset, method, steering, line, line_kernels, line_start)?;
    Ok((
        stack.method.name(),
        stack.steering.name(),
        stack.line.name(),
    ))
}
