#!/bin/sh
# Every subcommand has its own man page, l6470emu-SUB(1), made from its --help (ctest
# `subcommand_manpages`): each page exists, names the subcommand, reads as ASCII under LC_ALL=C,
# and run's lists the options CI users need. Usage: subcommand_manpages_test.sh DIR SUB...
fail() { echo "subcommand_manpages_test: FAIL: $*" >&2; exit 1; }
command -v man >/dev/null 2>&1 || { echo "subcommand_manpages_test: man is missing (man-db): skipped"; exit 77; }
dir=$1
shift
for sub in "$@"; do
  page=$dir/l6470emu-$sub.1.gz
  [ -f "$page" ] || fail "no page $page"
  text=$(LC_ALL=C MANWIDTH=100 man -l "$page" 2>/dev/null) || fail "man cannot read $page"
  words=$(echo "$sub" | tr '-' ' ')
  echo "$text" | grep -q "l6470emu $words" || fail "l6470emu-$sub(1) does not name 'l6470emu $words'"
  echo "$text" | LC_ALL=C grep -q '[^[:print:][:space:]]' && fail "l6470emu-$sub(1) has characters C cannot show"
done
run=$(LC_ALL=C MANWIDTH=100 man -l "$dir/l6470emu-run.1.gz" 2>/dev/null)
for option in --scenario --junit --timeout --coverage --record; do
  echo "$run" | grep -q -- "$option" || fail "l6470emu-run(1) lacks $option"
done
echo "subcommand_manpages_test: $# pages, passed"
