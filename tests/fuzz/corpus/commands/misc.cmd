set resolution 64x48
show
set exposure 1
ambient 0.5 255,255,255
source a.rt
quit
