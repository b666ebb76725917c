// The POV-Ray 3.7 twin of scenes/grid.rt, for `make bench`: the same camera,
// field of view, light, spheres, plane, Phong highlights, reflection 0.2,
// no anti-aliasing, 1920x1080 (set on the command line: +W1920 +H1080 -A).
// rtsh mixes a mirror as (1 - r) local + r reflected; POV-Ray adds
// r reflected to the local terms, so the local terms of the reflective
// spheres are scaled by 0.8 here. Colours are sRGB as in the .rt file,
// lighting is linear (assumed_gamma 1). rtsh's depth 5 = 5 bounces after
// the primary ray: max_trace_level 6.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 6 ambient_light rgb 1 }

camera {
  perspective
  location <0, 5, -9.5>
  look_at <0, 5, -9.5> + <0, -0.45, 1>
  right x * 1920 / 1080
  up y
  angle 60
}

light_source { <-6, 10, -8> color rgb 0.9 }

plane { y, 0
  pigment { color srgb <200, 200, 200> / 255 }
  finish { ambient 0.2 diffuse 0.9 phong 0.9 phong_size 200 }
}

#declare Red = texture {
  pigment { color srgb <220, 60, 50> / 255 }
  finish { ambient 0.16 diffuse 0.72 phong 0.72 phong_size 200 reflection { 0.2 } }
}
#declare White = texture {
  pigment { color srgb <240, 240, 240> / 255 }
  finish { ambient 0.2 diffuse 0.9 phong 0.9 phong_size 200 }
}
sphere { <-4.5, 0.4, -4.5>, 0.4 texture { Red } }
sphere { <-4.5, 0.4, -3.5>, 0.4 texture { White } }
sphere { <-4.5, 0.4, -2.5>, 0.4 texture { Red } }
sphere { <-4.5, 0.4, -1.5>, 0.4 texture { White } }
sphere { <-4.5, 0.4, -0.5>, 0.4 texture { Red } }
sphere { <-4.5, 0.4, 0.5>, 0.4 texture { White } }
sphere { <-4.5, 0.4, 1.5>, 0.4 texture { Red } }
sphere { <-4.5, 0.4, 2.5>, 0.4 texture { White } }
sphere { <-4.5, 0.4, 3.5>, 0.4 texture { Red } }
sphere { <-4.5, 0.4, 4.5>, 0.4 texture { White } }
sphere { <-3.5, 0.4, -4.5>, 0.4 texture { White } }
sphere { <-3.5, 0.4, -3.5>, 0.4 texture { Red } }
sphere { <-3.5, 0.4, -2.5>, 0.4 texture { White } }
sphere { <-3.5, 0.4, -1.5>, 0.4 texture { Red } }
sphere { <-3.5, 0.4, -0.5>, 0.4 texture { White } }
sphere { <-3.5, 0.4, 0.5>, 0.4 texture { Red } }
sphere { <-3.5, 0.4, 1.5>, 0.4 texture { White } }
sphere { <-3.5, 0.4, 2.5>, 0.4 texture { Red } }
sphere { <-3.5, 0.4, 3.5>, 0.4 texture { White } }
sphere { <-3.5, 0.4, 4.5>, 0.4 texture { Red } }
sphere { <-2.5, 0.4, -4.5>, 0.4 texture { Red } }
sphere { <-2.5, 0.4, -3.5>, 0.4 texture { White } }
sphere { <-2.5, 0.4, -2.5>, 0.4 texture { Red } }
sphere { <-2.5, 0.4, -1.5>, 0.4 texture { White } }
sphere { <-2.5, 0.4, -0.5>, 0.4 texture { Red } }
sphere { <-2.5, 0.4, 0.5>, 0.4 texture { White } }
sphere { <-2.5, 0.4, 1.5>, 0.4 texture { Red } }
sphere { <-2.5, 0.4, 2.5>, 0.4 texture { White } }
sphere { <-2.5, 0.4, 3.5>, 0.4 texture { Red } }
sphere { <-2.5, 0.4, 4.5>, 0.4 texture { White } }
sphere { <-1.5, 0.4, -4.5>, 0.4 texture { White } }
sphere { <-1.5, 0.4, -3.5>, 0.4 texture { Red } }
sphere { <-1.5, 0.4, -2.5>, 0.4 texture { White } }
sphere { <-1.5, 0.4, -1.5>, 0.4 texture { Red } }
sphere { <-1.5, 0.4, -0.5>, 0.4 texture { White } }
sphere { <-1.5, 0.4, 0.5>, 0.4 texture { Red } }
sphere { <-1.5, 0.4, 1.5>, 0.4 texture { White } }
sphere { <-1.5, 0.4, 2.5>, 0.4 texture { Red } }
sphere { <-1.5, 0.4, 3.5>, 0.4 texture { White } }
sphere { <-1.5, 0.4, 4.5>, 0.4 texture { Red } }
sphere { <-0.5, 0.4, -4.5>, 0.4 texture { Red } }
sphere { <-0.5, 0.4, -3.5>, 0.4 texture { White } }
sphere { <-0.5, 0.4, -2.5>, 0.4 texture { Red } }
sphere { <-0.5, 0.4, -1.5>, 0.4 texture { White } }
sphere { <-0.5, 0.4, -0.5>, 0.4 texture { Red } }
sphere { <-0.5, 0.4, 0.5>, 0.4 texture { White } }
sphere { <-0.5, 0.4, 1.5>, 0.4 texture { Red } }
sphere { <-0.5, 0.4, 2.5>, 0.4 texture { White } }
sphere { <-0.5, 0.4, 3.5>, 0.4 texture { Red } }
sphere { <-0.5, 0.4, 4.5>, 0.4 texture { White } }
sphere { <0.5, 0.4, -4.5>, 0.4 texture { White } }
sphere { <0.5, 0.4, -3.5>, 0.4 texture { Red } }
sphere { <0.5, 0.4, -2.5>, 0.4 texture { White } }
sphere { <0.5, 0.4, -1.5>, 0.4 texture { Red } }
sphere { <0.5, 0.4, -0.5>, 0.4 texture { White } }
sphere { <0.5, 0.4, 0.5>, 0.4 texture { Red } }
sphere { <0.5, 0.4, 1.5>, 0.4 texture { White } }
sphere { <0.5, 0.4, 2.5>, 0.4 texture { Red } }
sphere { <0.5, 0.4, 3.5>, 0.4 texture { White } }
sphere { <0.5, 0.4, 4.5>, 0.4 texture { Red } }
sphere { <1.5, 0.4, -4.5>, 0.4 texture { Red } }
sphere { <1.5, 0.4, -3.5>, 0.4 texture { White } }
sphere { <1.5, 0.4, -2.5>, 0.4 texture { Red } }
sphere { <1.5, 0.4, -1.5>, 0.4 texture { White } }
sphere { <1.5, 0.4, -0.5>, 0.4 texture { Red } }
sphere { <1.5, 0.4, 0.5>, 0.4 texture { White } }
sphere { <1.5, 0.4, 1.5>, 0.4 texture { Red } }
sphere { <1.5, 0.4, 2.5>, 0.4 texture { White } }
sphere { <1.5, 0.4, 3.5>, 0.4 texture { Red } }
sphere { <1.5, 0.4, 4.5>, 0.4 texture { White } }
sphere { <2.5, 0.4, -4.5>, 0.4 texture { White } }
sphere { <2.5, 0.4, -3.5>, 0.4 texture { Red } }
sphere { <2.5, 0.4, -2.5>, 0.4 texture { White } }
sphere { <2.5, 0.4, -1.5>, 0.4 texture { Red } }
sphere { <2.5, 0.4, -0.5>, 0.4 texture { White } }
sphere { <2.5, 0.4, 0.5>, 0.4 texture { Red } }
sphere { <2.5, 0.4, 1.5>, 0.4 texture { White } }
sphere { <2.5, 0.4, 2.5>, 0.4 texture { Red } }
sphere { <2.5, 0.4, 3.5>, 0.4 texture { White } }
sphere { <2.5, 0.4, 4.5>, 0.4 texture { Red } }
sphere { <3.5, 0.4, -4.5>, 0.4 texture { Red } }
sphere { <3.5, 0.4, -3.5>, 0.4 texture { White } }
sphere { <3.5, 0.4, -2.5>, 0.4 texture { Red } }
sphere { <3.5, 0.4, -1.5>, 0.4 texture { White } }
sphere { <3.5, 0.4, -0.5>, 0.4 texture { Red } }
sphere { <3.5, 0.4, 0.5>, 0.4 texture { White } }
sphere { <3.5, 0.4, 1.5>, 0.4 texture { Red } }
sphere { <3.5, 0.4, 2.5>, 0.4 texture { White } }
sphere { <3.5, 0.4, 3.5>, 0.4 texture { Red } }
sphere { <3.5, 0.4, 4.5>, 0.4 texture { White } }
sphere { <4.5, 0.4, -4.5>, 0.4 texture { White } }
sphere { <4.5, 0.4, -3.5>, 0.4 texture { Red } }
sphere { <4.5, 0.4, -2.5>, 0.4 texture { White } }
sphere { <4.5, 0.4, -1.5>, 0.4 texture { Red } }
sphere { <4.5, 0.4, -0.5>, 0.4 texture { White } }
sphere { <4.5, 0.4, 0.5>, 0.4 texture { Red } }
sphere { <4.5, 0.4, 1.5>, 0.4 texture { White } }
sphere { <4.5, 0.4, 2.5>, 0.4 texture { Red } }
sphere { <4.5, 0.4, 3.5>, 0.4 texture { White } }
sphere { <4.5, 0.4, 4.5>, 0.4 texture { Red } }
