#!/usr/bin/env bash
# A dry run of deploy/slurm/cosdem.sbatch without Slurm: `scontrol` and `srun` are
# replaced by shims (one "node", 127.0.0.1, one worker started by the fake srun), so the
# script's own logic runs for real: token creation and mode check, worker start, health
# wait, the master run with the node-derived --workers, and the workers' shutdown by trap.
#
#   deploy/test/slurm-test.sh --bin-dir DIR [--job FILE]
#
# DIR holds cosdem and cosdem-worker (the real binaries or the stand-in). The run's
# curve.csv must equal that of an in-process `cosdem run JOB`. Bounded by timeouts.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
bin_dir=""
job="$repo/examples/quick.toml"
while [[ $# -gt 0 ]]; do
    case "$1" in
        --bin-dir) bin_dir="$2"; shift 2 ;;
        --job) job="$2"; shift 2 ;;
        *) echo "slurm-test.sh: unknown argument: $1" >&2; exit 2 ;;
    esac
done
die() { echo "slurm-test: FAIL: $*" >&2; exit 1; }
[[ -n "$bin_dir" ]] || die "--bin-dir is required"
[[ -x "$bin_dir/cosdem" && -x "$bin_dir/cosdem-worker" ]] || die "cosdem or cosdem-worker missing in $bin_dir"
[[ -f "$job" ]] || die "job file not found: $job"
bin_dir="$(cd "$bin_dir" && pwd)"
job="$(cd "$(dirname "$job")" && pwd)/$(basename "$job")"

tmp="$(mktemp -d "${TMPDIR:-/tmp}/cosdem-slurm-test.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/shims" "$tmp/home"

cat >"$tmp/shims/scontrol" <<'EOF'
#!/usr/bin/env bash
# shim: `scontrol show hostnames LIST` prints one name per comma-separated entry
[[ "$1 $2" == "show hostnames" ]] || exit 2
tr ',' '\n' <<<"$3"
EOF
cat >"$tmp/shims/srun" <<'EOF'
#!/usr/bin/env bash
# shim: drop srun's options, run the command once (one node), record its pid
while [[ "$1" == -* ]]; do shift; done
echo $$ >"$SHIM_SRUN_PIDFILE"
exec "$@"
EOF
chmod +x "$tmp/shims/scontrol" "$tmp/shims/srun"

port=$((20000 + $$ % 20000))
"$bin_dir/cosdem" run "$job" --out "$tmp/ref" >"$tmp/ref.log" 2>&1 || { cat "$tmp/ref.log" >&2; die "reference run failed"; }

if ! (cd "$tmp" && env PATH="$tmp/shims:$PATH" HOME="$tmp/home" SHIM_SRUN_PIDFILE="$tmp/srun.pid" \
    SLURM_JOB_NODELIST=127.0.0.1 SLURM_JOB_ID=42 SLURM_CPUS_PER_TASK=1 SLURM_SUBMIT_DIR="$tmp" \
    COSDEM_BIN="$bin_dir" COSDEM_PORT="$port" COSDEM_HEALTH_TIMEOUT=30 \
    timeout 600 bash "$repo/deploy/slurm/cosdem.sbatch" "$job" "$tmp/out" >"$tmp/sbatch.log" 2>&1); then
    cat "$tmp/sbatch.log" >&2
    die "cosdem.sbatch failed"
fi
[[ "$(stat -c %a "$tmp/home/.cosdem/token")" == 600 ]] || die "the token was not created with mode 0600"
grep -q "1 workers serving: 127.0.0.1:$port" "$tmp/sbatch.log" || die "unexpected worker list: $(cat "$tmp/sbatch.log")"
cmp "$tmp/ref/curve.csv" "$tmp/out/curve.csv" || die "curve.csv differs from the in-process run"
wpid="$(cat "$tmp/srun.pid")"
for _ in $(seq 50); do kill -0 "$wpid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$wpid" 2>/dev/null; then
    kill -KILL "$wpid"
    die "the worker was still running after the batch script ended"
fi

# A token readable by others must be refused.
chmod 0644 "$tmp/home/.cosdem/token"
if (cd "$tmp" && env PATH="$tmp/shims:$PATH" HOME="$tmp/home" SHIM_SRUN_PIDFILE="$tmp/srun2.pid" \
    SLURM_JOB_NODELIST=127.0.0.1 SLURM_SUBMIT_DIR="$tmp" COSDEM_BIN="$bin_dir" COSDEM_PORT="$port" \
    timeout 60 bash "$repo/deploy/slurm/cosdem.sbatch" "$job" "$tmp/out2" >"$tmp/sbatch2.log" 2>&1); then
    die "cosdem.sbatch accepted a token file of mode 0644"
fi
grep -q "make it private" "$tmp/sbatch2.log" || die "no clear message for a 0644 token: $(cat "$tmp/sbatch2.log")"

echo "slurm-test: OK: cosdem.sbatch ran the job through its worker, same curve.csv, worker stopped, loose token refused"
