examples/embed: examples/embed.c include/rtsh/rtsh.h
include/rtsh/rtsh.h:
