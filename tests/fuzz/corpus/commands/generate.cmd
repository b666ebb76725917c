generate 50 7
object 3 scale 1e10,1e10,1e10
save g.rt
load g.rt
next
prev
help
help object
