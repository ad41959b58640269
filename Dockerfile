# syntax=docker/dockerfile:1
# The foton image: the foton program with its integrator plugins beside it (where foton looks
# for them), the example scenes, and the entrypoint that maps a Kubernetes Indexed Job's
# JOB_COMPLETION_INDEX to a part of a frame or a cell of a sweep (deploy/docker/entrypoint.sh,
# docs/scale.md).
#
#   docker build -t foton .
#   docker run --rm -v "$PWD/out:/data" foton render /opt/foton/scenes/cornell-box.toml -o /data/cornell.png

# The build and the runtime are the same Debian release, so that the program finds the glibc
# it was linked against. Any Rust at least the workspace's rust-version will do.
ARG RUST_IMAGE=rust:1-bookworm
ARG RUNTIME_IMAGE=debian:bookworm-slim

FROM ${RUST_IMAGE} AS build
WORKDIR /src
COPY . .
# The program and every plugin of the workspace, not the test crates. Host and plugins come
# from this one build: a plugin built elsewhere is refused (its build identifier differs).
# The path plugin's x86-64-v3 copy (integrators/path/build.rs) goes to the subfolder where
# foton looks first on a processor that has that level.
RUN --mount=type=cache,target=/usr/local/cargo/registry \
    cargo build --release --locked --workspace --exclude foton-tests --exclude foton-test-panicky \
    && mkdir /out \
    && cp target/release/foton target/release/libfoton_*.so /out/ \
    && if [ -d target/release/x86-64-v3 ]; then cp -r target/release/x86-64-v3 /out/; fi

FROM ${RUNTIME_IMAGE}
# Not root: the jobs need only to read the scenes and write to the shared volume.
RUN groupadd --gid 10001 foton \
    && useradd --uid 10001 --gid 10001 --no-create-home --home-dir /nonexistent --shell /usr/sbin/nologin foton
COPY --from=build /out/ /opt/foton/
COPY scenes/ /opt/foton/scenes/
COPY deploy/docker/entrypoint.sh /usr/local/bin/foton-entrypoint
ENV PATH=/opt/foton:$PATH
USER 10001:10001
WORKDIR /data
ENTRYPOINT ["/usr/local/bin/foton-entrypoint"]
CMD ["--help"]
