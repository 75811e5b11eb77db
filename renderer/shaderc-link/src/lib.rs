//! Empty: this crate exists for the link directives of its build script.
