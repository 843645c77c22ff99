#!/usr/bin/env bash
# Build the cosdem container images FROM scratch, with no base image and no registry.
#
#   deploy/images/build-images.sh [--worker PATH] [--master PATH] [--tag TAG] [--only worker|master]
#
# For each binary it assembles a minimal root filesystem (the binary in /usr/local/bin,
# the shared libraries `ldd` lists and the dynamic loader at their host paths, /etc/passwd
# and /etc/group with the unprivileged user cosdem (uid/gid 10001), /etc/nsswitch.conf,
# /tmp) and runs `docker build` with Dockerfile.worker / Dockerfile.master beside this
# script. Images: cosdem-worker:TAG and cosdem-master:TAG (TAG defaults to "local").
# Defaults: target/release/cosdem-worker and target/release/cosdem of the repository.
# Scratch space: target/deploy-images/ (rebuilt on every run). Quiet on success unless
# -v is given; on failure the build log is printed.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"

worker_bin="$repo/target/release/cosdem-worker"
master_bin="$repo/target/release/cosdem"
tag="local"
only=""
verbose=0

usage() {
    sed -n '2,13s/^# \{0,1\}//p' "${BASH_SOURCE[0]}"
}

while [[ $# -gt 0 ]]; do
    case "$1" in
        --worker) worker_bin="$2"; shift 2 ;;
        --master) master_bin="$2"; shift 2 ;;
        --tag) tag="$2"; shift 2 ;;
        --only) only="$2"; shift 2 ;;
        -v|--verbose) verbose=1; shift ;;
        -h|--help) usage; exit 0 ;;
        *) echo "build-images.sh: unknown argument: $1" >&2; usage >&2; exit 2 ;;
    esac
done

die() { echo "build-images.sh: $*" >&2; exit 1; }

# Copy FILE into ROOT at the same absolute path, following symlinks.
copy_at_path() {
    local root="$1" file="$2"
    mkdir -p "$root$(dirname "$file")"
    cp -L "$file" "$root$file"
}

# Copy the shared libraries and the loader that BIN needs into ROOT.
copy_libs() {
    local root="$1" bin="$2" out line path
    if ! out="$(ldd "$bin" 2>&1)"; then
        case "$out" in
            *"not a dynamic executable"*|*"statically linked"*) return 0 ;;
            *) die "ldd $bin failed: $out" ;;
        esac
    fi
    case "$out" in *"statically linked"*) return 0 ;; esac
    while IFS= read -r line; do
        path=""
        if [[ "$line" == *"=> not found"* ]]; then
            die "$bin needs a library that is not installed: ${line%%=>*}"
        elif [[ "$line" =~ =\>\ (/[^ ]+) ]]; then
            path="${BASH_REMATCH[1]}"
        elif [[ "$line" =~ ^[[:space:]]*(/[^ ]+) ]]; then
            path="${BASH_REMATCH[1]}" # the dynamic loader, at the path the ELF names
        fi
        if [[ -n "$path" ]]; then
            copy_at_path "$root" "$path"
        fi
    done <<<"$out"
}

# Assemble the root filesystem for one image in DIR/rootfs (and DIR/owned).
assemble() {
    local dir="$1" bin="$2" name="$3" root
    root="$dir/rootfs"
    rm -rf "$dir"
    mkdir -p "$root/usr/local/bin" "$root/etc" "$root/tmp" "$root/run/secrets" \
        "$root/home/cosdem" "$dir/owned/runs"
    chmod 1777 "$root/tmp"
    install -m 0755 "$bin" "$root/usr/local/bin/$name"
    copy_libs "$root" "$bin"
    printf '%s\n' 'root:x:0:0:root:/root:/sbin/nologin' \
        'cosdem:x:10001:10001:cosdem:/home/cosdem:/sbin/nologin' >"$root/etc/passwd"
    printf '%s\n' 'root:x:0:' 'cosdem:x:10001:' >"$root/etc/group"
    printf '%s\n' 'passwd: files' 'group: files' 'hosts: files dns' >"$root/etc/nsswitch.conf"
}

build_one() {
    local kind="$1" bin="$2" name="$3" image="$4" dir log
    [[ -f "$bin" ]] || die "binary not found: $bin (build it with: cargo build --release -p cosdem-cli -p cosdem-worker-cli)"
    [[ -x "$bin" ]] || die "not executable: $bin"
    dir="$repo/target/deploy-images/$kind"
    assemble "$dir" "$bin" "$name"
    cp "$here/Dockerfile.$kind" "$dir/Dockerfile"
    log="$dir/build.log"
    if ! DOCKER_BUILDKIT="${DOCKER_BUILDKIT:-0}" docker build --pull=false -t "$image" "$dir" >"$log" 2>&1; then
        cat "$log" >&2
        die "docker build of $image failed"
    fi
    if [[ "$verbose" == 1 ]]; then
        echo "built $image from $bin ($(du -sh "$dir/rootfs" | cut -f1) rootfs):"
        (cd "$dir/rootfs" && find . -type f | sort | sed 's/^\./  /')
    fi
}

command -v docker >/dev/null || die "docker is not installed"
command -v ldd >/dev/null || die "ldd is not installed"

case "$only" in
    ""|worker|master) ;;
    *) die "--only takes worker or master, not: $only" ;;
esac
if [[ -z "$only" || "$only" == worker ]]; then
    build_one worker "$worker_bin" cosdem-worker "cosdem-worker:$tag"
fi
if [[ -z "$only" || "$only" == master ]]; then
    build_one master "$master_bin" cosdem "cosdem-master:$tag"
fi
