//! Example integrator plugin (skeleton; see docs/plugins.md).
