//! Budgets that bound what loading a scene may read and build, so a hostile or broken file (or a
//! mistyped path) fails with a clear error instead of exhausting memory.
//!
//! The defaults fit every scene the project knows with a wide margin (Sponza-class scenes have
//! ~0.26 M triangles and ~70 M texels) and keep a worst case within a few GB of host memory.
//! Each budget is raised with an environment variable (read by [`LoadLimits::from_env`], which
//! [`crate::Scene::load`] uses), or by passing [`LoadLimits`] to [`crate::Scene::load_with_limits`].

/// Every budget, with the environment variable that overrides it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadLimits {
    /// Triangles uploaded: a mesh placed by one node counts once (its world-space copy), a mesh
    /// placed by N ≥ 2 nodes once too when the scene is instanced (see `instance_above`), N times
    /// when it is flattened. Uploaded vertices are bounded by 3 × this (a triangle never needs
    /// more than three).
    pub max_triangles: u64,
    /// Mesh instances: placements of meshes that several nodes place.
    pub max_instances: u64,
    /// Repeated meshes are instanced only when the scene places more triangles than this;
    /// below it everything is flattened (on lavapipe the two-level traversal cost Sponza 1.2× its
    /// primary-ray rate and the large scene 3×, while flattening them costs 14–19 MiB).
    pub instance_above: u64,
    /// Texels of all decoded textures together (stored as RGBA8, 4 bytes each).
    pub max_texels: u64,
    /// Bytes read: the glTF/GLB file itself, its buffers and its encoded images together
    /// (data: URIs count with their decoded size).
    pub max_bytes: u64,
}

/// One budget's name, environment variable and default, for messages and documentation.
pub struct Budget {
    pub name: &'static str,
    pub env: &'static str,
    pub default: u64,
}

pub const TRIANGLES: Budget = Budget {
    name: "triangle",
    env: "FOVEA_MAX_TRIANGLES",
    default: 4_000_000,
};
pub const INSTANCES: Budget = Budget {
    name: "instance",
    env: "FOVEA_MAX_INSTANCES",
    default: 1_000_000,
};
pub const INSTANCE_ABOVE: Budget = Budget {
    name: "instancing threshold",
    env: "FOVEA_INSTANCE_ABOVE",
    default: 1_000_000,
};
pub const TEXELS: Budget = Budget {
    name: "texel",
    env: "FOVEA_MAX_TEXELS",
    default: 256 << 20,
};
pub const BYTES: Budget = Budget {
    name: "byte",
    env: "FOVEA_MAX_SCENE_BYTES",
    default: 2 << 30,
};

impl Default for LoadLimits {
    fn default() -> Self {
        LoadLimits {
            max_triangles: TRIANGLES.default,
            max_instances: INSTANCES.default,
            instance_above: INSTANCE_ABOVE.default,
            max_texels: TEXELS.default,
            max_bytes: BYTES.default,
        }
    }
}

impl Budget {
    fn read_env(&self) -> Result<u64, String> {
        match std::env::var(self.env) {
            Err(std::env::VarError::NotPresent) => Ok(self.default),
            Err(std::env::VarError::NotUnicode(_)) => {
                Err(format!("{} is not valid UTF-8", self.env))
            }
            Ok(text) => {
                let digits: String = text.trim().chars().filter(|&c| c != '_').collect();
                match digits.parse::<u64>() {
                    Ok(n) if n > 0 => Ok(n),
                    _ => Err(format!(
                        "{}='{}' must be a whole number above 0",
                        self.env,
                        text.escape_debug()
                    )),
                }
            }
        }
    }
}

impl LoadLimits {
    /// The defaults, each overridden by its environment variable when set.
    pub fn from_env() -> Result<LoadLimits, String> {
        Ok(LoadLimits {
            max_triangles: TRIANGLES.read_env()?,
            max_instances: INSTANCES.read_env()?,
            instance_above: INSTANCE_ABOVE.read_env()?,
            max_texels: TEXELS.read_env()?,
            max_bytes: BYTES.read_env()?,
        })
    }
}

/// The message for exceeding `budget`: what was asked for, the limit, and how to raise it.
pub(crate) fn over_budget(budget: &Budget, limit: u64, what: String) -> String {
    format!(
        "{what} exceeds the {} budget of {limit} (default {}); set {}=<n> to raise it",
        budget.name, budget.default, budget.env
    )
}

/// Bytes still allowed to be read; every read takes from it before allocating.
pub(crate) struct ByteBudget {
    limit: u64,
    used: u64,
}

impl ByteBudget {
    pub(crate) fn new(limit: u64) -> Self {
        ByteBudget { limit, used: 0 }
    }

    /// Reserves `n` bytes, or says what would exceed the budget.
    pub(crate) fn take(&mut self, n: u64, what: &str) -> Result<(), String> {
        match self
            .used
            .checked_add(n)
            .filter(|&total| total <= self.limit)
        {
            Some(total) => {
                self.used = total;
                Ok(())
            }
            None => Err(over_budget(
                &BYTES,
                self.limit,
                format!("{what} ({n} bytes, {} already read)", self.used),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_budget_refuses_what_does_not_fit_and_names_the_variable() {
        let mut b = ByteBudget::new(10);
        b.take(6, "a").unwrap();
        let err = b.take(5, "buffers[1]").unwrap_err();
        assert!(
            err.contains("buffers[1]")
                && err.contains("FOVEA_MAX_SCENE_BYTES")
                && err.contains("budget of 10"),
            "{err}"
        );
        assert!(b.take(u64::MAX, "huge").is_err(), "no overflow");
        b.take(4, "the rest")
            .expect("a refused take reserves nothing");
    }

    #[test]
    fn budget_values_parse_with_separators_and_refuse_junk() {
        // Uses a variable no other test sets, so the process environment stays race-free.
        let b = Budget {
            name: "test",
            env: "FOVEA_TEST_ONLY_LIMIT",
            default: 7,
        };
        assert_eq!(b.read_env(), Ok(7));
        std::env::set_var(b.env, "1_000");
        assert_eq!(b.read_env(), Ok(1000));
        std::env::set_var(b.env, "lots");
        assert!(b
            .read_env()
            .unwrap_err()
            .contains("FOVEA_TEST_ONLY_LIMIT='lots'"));
        std::env::set_var(b.env, "0");
        assert!(
            b.read_env().is_err(),
            "a zero budget would refuse every scene"
        );
        std::env::remove_var(b.env);
    }
}
