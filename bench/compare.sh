#!/usr/bin/env bash
# Side-by-side headline figures: the working tree's l6470emu_bench against another revision's,
# both Release, run alternately on the same machine in the same minutes, printed as ratios.
# It does not judge: a machine's load moves both columns; the ratio is what to read.
#
# Usage: bench/compare.sh REV [ROUNDS=3] [SECONDS=0.5]
#   REV      any git revision (commit, tag, branch, HEAD~3)
#   ROUNDS   runs of each benchmark, alternating (old, new, old, new, ...); each figure is
#            the median of its runs, shown with its range
#   SECONDS  seconds per measurement, passed to l6470emu_bench
# REV is built in a temporary git worktree under ${TMPDIR:-/tmp} (removed at exit; its build
# directory is kept in ~/.cache/l6470emu-compare/<commit> for the next comparison); the working
# tree's benchmark in build-compare/ (ignored by git). ccache is used when present.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { sed -n '5,13p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
rev=$1 rounds=${2:-3} seconds=${3:-0.5}
old_commit=$(git rev-parse --verify --quiet "$rev^{commit}") || { echo "compare.sh: '$rev' is no commit here" >&2; exit 2; }
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "compare.sh: ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2; }
python=/usr/bin/python3
[ -x "$python" ] || python=python3

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
build_bench() {  # build_bench SOURCE_DIR BUILD_DIR: a Release l6470emu_bench, quietly
  local log=$2/compare-build.log
  mkdir -p "$2"
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DL6470EMU_TESTS=OFF "${launcher[@]}" >"$log" 2>&1 &&
    cmake --build "$2" --target l6470emu_bench -j"$(nproc)" >>"$log" 2>&1 ||
    { echo "compare.sh: building $1 failed; see $log" >&2; tail -20 "$log" >&2; return 1; }
}

work=$(mktemp -d "${TMPDIR:-/tmp}/l6470emu-compare.XXXXXX")
tree=$work/tree
cleanup() {
  git worktree remove --force "$tree" >/dev/null 2>&1 || true
  rm -rf "$work"
  git worktree prune >/dev/null 2>&1 || true
}
trap cleanup EXIT

cache=${XDG_CACHE_HOME:-$HOME/.cache}/l6470emu-compare/$old_commit
mkdir -p "$cache"
old_bin=$cache/bench/l6470emu_bench
if [ ! -x "$old_bin" ]; then
  echo "building ${old_commit:0:10} (Release) in a temporary worktree ..." >&2
  git worktree add --detach --quiet "$tree" "$old_commit"
  build_bench "$tree" "$cache"
fi
echo "building the working tree (Release) in build-compare/ ..." >&2
build_bench "$PWD" "$PWD/build-compare"
new_bin=$PWD/build-compare/bench/l6470emu_bench

new_desc="working tree at $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- 2>/dev/null || echo ' + changes')"
old_desc="$rev = $(git rev-parse --short "$old_commit")"
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
for ((r = 1; r <= rounds; r++)); do
  echo "round $r of $rounds ..." >&2
  "$old_bin" "$seconds" >"$work/old.$r"
  "$new_bin" "$seconds" >"$work/new.$r"
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

"$python" - "$work" "$rounds" "$old_desc" "$new_desc" "$load_before" "$load_after" "$seconds" "$(nproc)" <<'EOF'
import re, statistics, sys
work, rounds, old_desc, new_desc, load_before, load_after, seconds, cpus = sys.argv[1:]
rounds = int(rounds)
SI = {"": 1, "k": 1e3, "M": 1e6, "G": 1e9}

def figures(path):
    """The headline figures of one l6470emu_bench run, by name; higher is better unless noted."""
    f = {}
    for line in open(path):
        m = re.match(r"\s+(\d+)\s+([\d.]+) ?([kMG]?)\s+([\d.]+) ?([kMG]?)B\s", line)
        if m:
            f[f"SPI {int(m[1]):>3} chips, frames/s"] = float(m[2]) * SI[m[3]]
            f[f"SPI {int(m[1]):>3} chips, bytes/s"] = float(m[4]) * SI[m[5]]
            cpu = re.search(r"x\s+(\d+)%", line)  # "on CPU" (since the column exists)
            if cpu and int(cpu[1]) > 0:
                f[f"SPI {int(m[1]):>3} chips, bytes per CPU s"] = float(m[4]) * SI[m[5]] * 100 / int(cpu[1])
            continue
        m = re.match(r"\s+(fast|fast\+axes|reference)\s+([\d.]+)x\s+(?:(\d+)%)?", line)
        if m:
            f[f"motion 64 chips, {m[1]}, x real time"] = float(m[2])
            if m[3] and int(m[3]) > 0:
                f[f"motion 64 chips, {m[1]}, x real time per CPU s"] = float(m[2]) * 100 / int(m[3])
        m = re.search(r"costs ([\d.]+)x the (?:CPU )?time without axes", line)
        if m:
            f["axes: time with / without (lower)"] = float(m[1])
        m = re.search(r"cross-check: .*: (.*)$", line)
        if m:
            f["cross-check"] = m[1].strip()
        m = re.match(r"\s+(Move 2\^21 microsteps, STEP_SEL \d|Run for 24 simulated hours)\S*\s+([\d.]+) us", line)
        if m:
            f[f"{m[1]}, us (lower)"] = float(m[2])
        m = re.match(r"\s+per chip in a Chain of 256.*?([\d.]+) bytes", line)
        if m:
            f["bytes per chip (lower)"] = float(m[1])
    return f

old = [figures(f"{work}/old.{r}") for r in range(1, rounds + 1)]
new = [figures(f"{work}/new.{r}") for r in range(1, rounds + 1)]
names = []
for run in old + new:
    for k in run:
        if k not in names:
            names.append(k)

def fmt(v):
    if isinstance(v, str):
        return v
    for div, unit in ((1e9, " G"), (1e6, " M"), (1e3, " k")):
        if v >= div:
            return f"{v / div:.3g}{unit}"
    return f"{v:.3g}"

def column(runs, k):
    vals = [r[k] for r in runs if k in r]
    if not vals:
        return None, "-"
    if isinstance(vals[0], str):
        return None, vals[0] if len(set(vals)) == 1 else " / ".join(sorted(set(vals)))
    med = statistics.median(vals)
    return med, fmt(med) if len(vals) == 1 else f"{fmt(med)} ({fmt(min(vals))}-{fmt(max(vals))})"

print(f"l6470emu headline figures, side by side: {rounds} alternating run(s) of each, {seconds} s per measurement")
print(f"  old: {old_desc}")
print(f"  new: {new_desc}")
print(f"  load average (1/5/15 min) on {cpus} CPUs: {load_before} before, {load_after} after")
print(f"  {'figure':<52} {'old: median (range)':>26} {'new: median (range)':>26} {'new/old':>8}")
for k in names:
    o, os_ = column(old, k)
    n, ns = column(new, k)
    ratio = f"{n / o:.2f}x" if o and n is not None else ""
    print(f"  {k:<52} {os_:>26} {ns:>26} {ratio:>8}")
print("  (lower) marks figures where less is better; elsewhere a ratio above 1 means the new build is faster")
print("  'per CPU s' divides by the share of wall time the benchmark ran (its 'on CPU' column, where it has one):")
print("  what an idle machine would show")
EOF
