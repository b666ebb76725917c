set samples 2
set mode path
set depth 3
render
save a.ppm
save b.pfm
save c.png
save d.ans
set
