// Empty: it exists so that cargo builds the build-dependencies that Cargo.toml lists only to
// unify features across the workspace's builds (see the comment there).
fn main() {}
