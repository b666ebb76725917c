#!/bin/sh
# Adds up the counts the runners left in the results folder.
passed=0 failed=0
for f in "$1"/*.count; do
	[ -f "$f" ] || continue
	read p q <"$f"
	passed=$((passed + p)); failed=$((failed + q))
done
echo "$passed passed, $failed failed"
[ $failed = 0 ]
