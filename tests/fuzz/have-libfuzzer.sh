#!/bin/sh
# Exits 0 when clang can build a libFuzzer target with ASan+UBSan.
command -v clang >/dev/null 2>&1 || exit 1
d=$(mktemp -d) || exit 1
printf '#include <stddef.h>\n#include <stdint.h>\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n);\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n' >"$d/t.c"
clang -fsanitize=fuzzer,address,undefined -o "$d/t" "$d/t.c" >/dev/null 2>&1; st=$?
rm -rf "$d"
exit $st
