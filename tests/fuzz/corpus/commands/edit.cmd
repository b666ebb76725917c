object 1 move 1,0,0; object 2 scale 2,2,2; object 3 rotate 0,45,0
camera move 0,0,1; camera turn 10,5; camera fov 70; camera lookat 0,1,0
light 1 color 255,120,60; light 1 brightness 0.5; light 1 move 1,1,1
add sp 0,3,0 1 255,255,0
delete object 2
undo; redo; undo
list
save a.rt
load a.rt
