#!/bin/sh
# The man page as a user in the C locale reads it (ctest `manpage`): pure ASCII roff, no "??"
# or "<micro>" for the characters the program's help writes in UTF-8 (cmake/manpage.cmake names
# them for groff), "us" for µs; and every subcommand has its section. Usage: manpage_test.sh PAGE
set -eu
page=$1
fail() { echo "manpage_test: FAIL: $*" >&2; exit 1; }
command -v man >/dev/null || { echo "SKIPPED: man missing (package man-db)"; exit 77; }
if LC_ALL=C grep -n '[^ -~	]' "$page" | head -3 | grep .; then fail "non-ASCII bytes in $page (lines above)"; fi
text=$(LC_ALL=C MANWIDTH=100 man -l "$page" 2>&1) || fail "man -l $page"
printf '%s\n' "$text" | grep -n '??\|<micro>\|warning' && fail "characters man could not show in ASCII (above)"
printf '%s\n' "$text" | grep -q 'looked at, in us' || fail "no 'in us' for the VCD sampling option"
for sub in demo tables serve ctl run campaign replay decode convert plot units; do
  printf '%s\n' "$text" | grep -q "^   $sub\$" || fail "no SUBCOMMANDS section for $sub"
done
utf8=$(LC_ALL=C.UTF-8 MANWIDTH=100 man -l "$page" 2>&1)
printf '%s\n' "$utf8" | grep -q 'looked at, in µs' || fail "no µs in a UTF-8 locale"
echo "manpage_test: passed"
