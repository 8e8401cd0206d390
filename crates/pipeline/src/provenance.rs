//! What every JSON sidecar says about its writer, so that a file can be read correctly years
//! later: the tool and its version, and the version of the sidecar's layout.

use serde_json::{Value, json};

/// Version of the sidecar layout; raised when a key is renamed or changes meaning.
pub const SCHEMA_VERSION: u32 = 1;

/// `value` (a JSON object) with `tool` (`{"name", "version"}`) and `schema_version` added.
pub fn stamped(mut value: Value) -> Value {
    if let Value::Object(obj) = &mut value {
        obj.insert(
            "tool".into(),
            json!({"name": "het-bssrdf", "version": env!("CARGO_PKG_VERSION")}),
        );
        obj.insert("schema_version".into(), json!(SCHEMA_VERSION));
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_tool_version_and_schema() {
        let v = stamped(json!({"spp": 4}));
        assert_eq!(v["spp"], 4);
        assert_eq!(v["tool"]["name"], "het-bssrdf");
        assert_eq!(v["tool"]["version"], env!("CARGO_PKG_VERSION"));
        assert_eq!(v["schema_version"], SCHEMA_VERSION);
    }
}
