//! Workspace integration tests (one binary; modules per theme).
