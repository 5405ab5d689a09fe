#!/usr/bin/env bash
# The message path's section ordering (linux/preload/hot_path.order) still names functions the
# preload library has, and the link placed them side by side: every listed function is in the
# library, and together they span little more than their own size. A rename on the message path
# fails here until scripts/hot_path_order.sh is run again.
# Usage: hot_path_order_test.sh ORDER_FILE LIBRARY
set -euo pipefail
order=$1 lib=$2
/usr/bin/python3 - "$order" "$lib" <<'EOF'
import subprocess, sys
order, lib = sys.argv[1:3]
listed = [l.strip()[len(".text."):] for l in open(order) if l.startswith(".text.")]
# nm: address, size, type, name of every defined function (local ones too: the library hides them).
funcs = {}
for line in subprocess.run(["nm", "--defined-only", "--print-size", lib], capture_output=True, text=True, check=True).stdout.splitlines():
    parts = line.split()
    if len(parts) == 4 and parts[2] in "tTwW":
        funcs[parts[3]] = (int(parts[0], 16), int(parts[1], 16))
missing = [f for f in listed if f not in funcs]
if missing:
    print(f"{len(missing)} of the {len(listed)} functions in {order} are not in {lib}:")
    for f in missing[:20]:
        print("  " + f)
    print("the message path changed: run scripts/hot_path_order.sh BUILD_DIR and commit the new list")
    sys.exit(1)
spans = [funcs[f] for f in listed]
start = min(a for a, _ in spans)
end = max(a + s for a, s in spans)
size = sum(s for _, s in spans)
print(f"{len(listed)} functions, {size} bytes of code, placed within {end - start} bytes")
# Side by side: padding between them (alignment) at most doubles the span.
if end - start > 2 * size:
    print(f"they are spread over {end - start} bytes: the link did not apply {order}")
    sys.exit(1)
EOF
