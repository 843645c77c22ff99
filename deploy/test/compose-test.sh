#!/usr/bin/env bash
# The deployment test: cosdem in containers, with a worker killed and another cut off
# from the network during steps, must give results byte-identical to an in-process run.
#
#   deploy/test/compose-test.sh [--bin-dir DIR] [--job FILE] [--tag TAG] [--no-build]
#
#   --bin-dir DIR  where cosdem and cosdem-worker are (default: target/release, built
#                  first with `cargo build --release --locked -p cosdem-cli -p cosdem-worker-cli`
#                  unless --no-build)
#   --job FILE     the job file (default: deploy/test/job.toml, slow enough for the faults
#                  to land during steps)
#   --tag TAG      image tag to build and run (default: local)
#
# Steps: build the images (deploy/images/build-images.sh); run the in-process reference
# `cosdem run JOB --out REF`; bring up deploy/compose/compose.yaml (3 workers, 1 master)
# with a fresh random token; when curve.csv has K1 lines, `docker kill` worker-1; when it
# has K2 lines, `docker network disconnect` worker-2; wait for the master; compare
# curve.csv, fields.pvd, gauss.pvd and every vtk/*.vtu with the reference byte for byte.
# K1 and K2 default to 1/3 and 2/3 of the reference's line count (env COSDEM_TEST_K1/K2).
# COSDEM_TEST_VERBOSE=1 prints the master's log and the containers' states at the end;
# COSDEM_TEST_KEEP=DIR keeps both run directories (DIR/ref, DIR/run) after a success.
# Every wait is bounded (COSDEM_TEST_TIMEOUT seconds for each run, default 600); the
# compose project is torn down (`down -v`) on exit. Prints SKIP and exits 0 when no
# Docker engine answers. Quiet on success but for one closing line (with phase times).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
compose_file="$repo/deploy/compose/compose.yaml"

bin_dir=""
job="$here/job.toml"
tag="local"
build=1
run_timeout="${COSDEM_TEST_TIMEOUT:-600}"

while [[ $# -gt 0 ]]; do
    case "$1" in
        --bin-dir) bin_dir="$2"; shift 2 ;;
        --job) job="$2"; shift 2 ;;
        --tag) tag="$2"; shift 2 ;;
        --no-build) build=0; shift ;;
        -h|--help) sed -n '2,24s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"; exit 0 ;;
        *) echo "compose-test.sh: unknown argument: $1" >&2; exit 2 ;;
    esac
done

say() { echo "compose-test: $*" >&2; }
# Phase times for the closing line: `phase NAME` ends the phase started by the previous call.
times=""
phase_start=$SECONDS
phase() { times+="${times:+, }$1 $((SECONDS - phase_start))s"; phase_start=$SECONDS; }
die() { say "FAIL: $*"; exit 1; }

if ! docker info >/dev/null 2>&1; then
    echo "compose-test: SKIP: no Docker engine answers (docker info failed)"
    exit 0
fi

if docker compose version >/dev/null 2>&1; then
    compose=(docker compose)
elif command -v docker-compose >/dev/null; then
    compose=(docker-compose)
else
    die "neither 'docker compose' nor 'docker-compose' is installed"
fi

if [[ -z "$bin_dir" ]]; then
    bin_dir="$repo/target/release"
    if [[ "$build" == 1 ]]; then
        command -v cargo >/dev/null || die "cargo not found (or pass --bin-dir / --no-build)"
        log="$(mktemp)"
        if ! (cd "$repo" && cargo build --release --locked -p cosdem-cli -p cosdem-worker-cli) >"$log" 2>&1; then
            cat "$log" >&2
            rm -f "$log"
            die "cargo build --release failed"
        fi
        rm -f "$log"
        phase build
    fi
fi
for b in cosdem cosdem-worker; do
    [[ -x "$bin_dir/$b" ]] || die "$bin_dir/$b is missing: the release binaries do not exist yet" \
        "(they come with the master and worker CLIs; build with" \
        "'cargo build --release -p cosdem-cli -p cosdem-worker-cli')"
done
[[ -f "$job" ]] || die "job file not found: $job"
bin_dir="$(cd "$bin_dir" && pwd)"

tmp="$(mktemp -d "${TMPDIR:-/tmp}/cosdem-compose-test.XXXXXX")"
project="cosdemtest$$"
compose_up=0

dc() {
    COSDEM_TAG="$tag" \
    COSDEM_TOKEN_FILE="$tmp/secret/token" \
    COSDEM_JOB_DIR="$tmp/job" \
    COSDEM_JOB="$(basename "$job")" \
    COSDEM_RUNS="$tmp/runs" \
    COSDEM_RUN_NAME="run" \
    COSDEM_WORKER_RESTART="no" \
        timeout 300 "${compose[@]}" -f "$compose_file" -p "$project" "$@"
}

cleanup() {
    local rc=$?
    if [[ "$compose_up" == 1 ]]; then
        if [[ "$rc" != 0 ]]; then
            say "last container logs:"
            dc logs --no-color --tail 30 >&2 2>&1 || true
        fi
        dc down -v --remove-orphans -t 5 >/dev/null 2>&1 || say "warning: compose down failed for project $project"
    fi
    rm -rf "$tmp" || true
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Inputs for the containers: a random token (the secret; readable by the container's
# unprivileged user, inside a directory only root can enter), the job file, and a run
# directory the unprivileged user can write.
mkdir -p "$tmp/secret" "$tmp/job" "$tmp/runs"
chmod 0700 "$tmp/secret"
head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \n' >"$tmp/secret/token"
chmod 0644 "$tmp/secret/token"
install -m 0644 "$job" "$tmp/job/"
chmod 0755 "$tmp" "$tmp/job"
chmod 0777 "$tmp/runs"

# Images.
"$repo/deploy/images/build-images.sh" --worker "$bin_dir/cosdem-worker" --master "$bin_dir/cosdem" --tag "$tag"
phase images

# The in-process reference.
if ! timeout "$run_timeout" "$bin_dir/cosdem" run "$job" --out "$tmp/ref" >"$tmp/ref.log" 2>&1; then
    cat "$tmp/ref.log" >&2
    die "the in-process reference run failed"
fi
[[ -s "$tmp/ref/curve.csv" ]] || die "the reference run wrote no curve.csv"
total="$(wc -l <"$tmp/ref/curve.csv")"
k1="${COSDEM_TEST_K1:-$((total / 3))}"
k2="${COSDEM_TEST_K2:-$((2 * total / 3))}"
((k1 >= 1)) || k1=1
((k2 > k1)) || k2=$((k1 + 1))
((k2 < total)) || die "the job is too short for two faults: curve.csv has $total lines, need more than $k2"
phase reference

# The deployment.
compose_up=1
if ! dc up -d >"$tmp/up.log" 2>&1; then
    cat "$tmp/up.log" >&2
    die "compose up failed (workers unhealthy?)"
fi
phase "compose up (workers healthy)"
# Container ids by compose labels (the docker CLI answers faster than docker-compose v1,
# which matters when steps are short and the machine is busy).
cid() {
    docker ps -aq --filter "label=com.docker.compose.project=$project" \
        --filter "label=com.docker.compose.service=$1"
}
master="$(cid master)"
w1="$(cid worker-1)"
w2="$(cid worker-2)"
[[ -n "$master" && -n "$w1" && -n "$w2" ]] || die "containers not found after compose up"
network="$(docker network ls -q --filter "label=com.docker.compose.project=$project" \
    --filter "label=com.docker.compose.network=cosdem")"
[[ -n "$network" ]] || die "the compose network was not found"
curve="$tmp/runs/run/curve.csv"
deadline=$((SECONDS + run_timeout))

running() { [[ "$(docker inspect -f '{{.State.Running}}' "$1")" == true ]]; }
lines() { if [[ -f "$curve" ]]; then wc -l <"$curve"; else echo 0; fi; }

# Wait until curve.csv has at least N lines while the master still runs.
wait_lines() {
    local n="$1"
    while (($(lines) < n)); do
        running "$master" || die "the master stopped before curve.csv reached $n lines" \
            "(exit code $(docker inspect -f '{{.State.ExitCode}}' "$master"))"
        ((SECONDS < deadline)) || die "timeout: curve.csv did not reach $n lines in ${run_timeout}s"
        sleep 0.2
    done
    running "$master" || die "the master finished before the fault at line $n could be injected (job too short)"
}

wait_lines "$k1"
docker kill "$w1" >/dev/null
wait_lines "$k2"
docker network disconnect -f "$network" "$w2" >/dev/null

while running "$master"; do
    ((SECONDS < deadline)) || die "timeout: the master did not finish in ${run_timeout}s"
    sleep 1
done
code="$(docker inspect -f '{{.State.ExitCode}}' "$master")"
[[ "$code" == 0 ]] || die "the master exited with code $code"
phase "compose run"
! running "$w1" || die "worker-1 is running again after docker kill (restart policy?)"

# Byte-identical results. On a difference both run directories are kept in
# target/deploy-test-failed/{ref,run} and the curves' differing lines are printed.
out="$tmp/runs/run"
differs() {
    local keep="$repo/target/deploy-test-failed"
    rm -rf "$keep"
    mkdir -p "$keep"
    cp -r "$tmp/ref" "$keep/ref"
    cp -r "$out" "$keep/run"
    dc logs --no-color master >"$keep/master-container.log" 2>&1 || true
    say "curve.csv, in-process (<) vs. deployed (>):"
    diff "$tmp/ref/curve.csv" "$out/curve.csv" | head -n 20 >&2 || true
    die "$1 differs from the in-process run (both runs kept in $keep)"
}
cmp -s "$tmp/ref/curve.csv" "$out/curve.csv" || differs curve.csv
for f in fields.pvd gauss.pvd; do
    [[ -f "$tmp/ref/$f" ]] || die "the reference run wrote no $f"
    cmp -s "$tmp/ref/$f" "$out/$f" || differs "$f"
done
ref_vtu="$(cd "$tmp/ref" && find vtk -name '*.vtu' 2>/dev/null | sort)"
out_vtu="$(cd "$out" && find vtk -name '*.vtu' 2>/dev/null | sort)"
[[ "$ref_vtu" == "$out_vtu" ]] || die "the sets of vtk/*.vtu files differ"
nvtu=0
while IFS= read -r f; do
    [[ -n "$f" ]] || continue
    cmp -s "$tmp/ref/$f" "$out/$f" || differs "$f"
    nvtu=$((nvtu + 1))
done <<<"$ref_vtu"

if [[ -n "${COSDEM_TEST_KEEP:-}" ]]; then
    mkdir -p "$COSDEM_TEST_KEEP"
    rm -rf "$COSDEM_TEST_KEEP/ref" "$COSDEM_TEST_KEEP/run"
    cp -r "$tmp/ref" "$COSDEM_TEST_KEEP/ref"
    cp -r "$out" "$COSDEM_TEST_KEEP/run"
fi
if [[ "${COSDEM_TEST_VERBOSE:-0}" == 1 ]]; then
    dc logs --no-color master >&2 2>&1 || true
    docker ps -a --filter "label=com.docker.compose.project=$project" >&2
fi
echo "compose-test: OK: curve.csv ($total lines), fields.pvd, gauss.pvd and $nvtu .vtu files" \
    "byte-identical to the in-process run, with worker-1 killed after line $k1 and worker-2" \
    "disconnected after line $k2; times: $times"
