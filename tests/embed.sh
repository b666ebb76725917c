#!/bin/sh
# Turns a text file into a C string literal (one line of source per line),
# for scenes compiled into the binary.
sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/^/"/' -e 's/$/\\n"/' "$1"
