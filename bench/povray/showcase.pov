// data/scenes/showcase.json for POV-Ray 3.7. The trefoil mesh is read from trefoil.inc, which
// scripts/compare-povray writes from data/scenes/meshes/trefoil.off (a mesh2 of the same
// triangles). Rounded boxes are shapes.inc's Round_Box, the same spheres, cylinders and boxes
// as csgrt's rounded_box.
#include "common.inc"
#include "shapes.inc"
#include "trefoil.inc"
Camera(<0, 4.6, 11.5>, <0, 0.9, 0>, 38)
PointLight(<-6, 10, 8>, <190, 175, 150>)
DirectionalLight(<0.5, -1, -0.35>, <0.55, 0.6, 0.7>)
#declare Floor = texture { Albedo(0.62, 0.6, 0.56) }
#declare Blue = texture { Albedo(0.16, 0.34, 0.72) }
#declare Red = texture { Albedo(0.75, 0.16, 0.12) }
#declare Gold = texture { Albedo(0.85, 0.62, 0.2) }
#declare Green = texture { Albedo(0.22, 0.55, 0.3) }
#declare Steel = texture { Albedo(0.55, 0.57, 0.6) }
#declare Ivory = texture { Albedo(0.9, 0.86, 0.76) }
#declare Teal = texture { Albedo(0.1, 0.5, 0.52) }

#declare HexNut = difference {
  intersection {
    box { <-0.5, 0, -1>, <0.5, 0.42, 1> }
    box { <-0.5, 0, -1>, <0.5, 0.42, 1> Turn(y, 60) }
    box { <-0.5, 0, -1>, <0.5, 0.42, 1> Turn(y, 120) }
  }
  cylinder { <0, -1, 0>, <0, 1, 0>, 0.26 }
}
#declare DrilledBlock = difference {
  intersection {
    object { Round_Box_Union(<-1, -1, -1>, <1, 1, 1>, 0.12) }
    sphere { 0, 1.36 }
  }
  cylinder { <-2, 0, 0>, <2, 0, 0>, 0.56 }
  cylinder { <0, -2, 0>, <0, 2, 0>, 0.56 }
  cylinder { <0, 0, -2>, <0, 0, 2>, 0.56 }
}

plane { y, 0 texture { Floor } }
object { DrilledBlock texture { Red } Turn(y, 32) translate <1.3, 1, -0.9> }
// thick ring: y 0..0.45, radii 0.72..1.12
difference {
  cylinder { <0, 0, 0>, <0, 0.45, 0>, 1.12 }
  cylinder { <0, -0.01, 0>, <0, 0.46, 0>, 0.72 }
  texture { Gold } translate <-4.4, 0, 1.2>
}
// bowl: the shell between radii 0.93 and 1.05 below its rim at y = 0
difference {
  sphere { 0, 1.05 }
  sphere { 0, 0.93 }
  plane { -y, 0 }
  texture { Blue } Turn(x, 20) translate <-3.9, 1.05, -2.4>
}
sphere { <-3.9, 0.571, -2.574>, 0.42 texture { Ivory } }
object { HexNut texture { Steel } Turn(y, 10) translate <3.5, 0, 2.4> }
object { HexNut texture { Steel } Turn(y, 35) translate <4.9, 0, 1.7> }
object { HexNut texture { Steel } translate <0, -0.21, 0> Turn(x, 90) Turn(y, -25)
         translate <4.3, 1.0, 3.1> }
// cut-away globe: phi 15..285
sphere { 0, 1.1 clipped_by { PhiWedge(15, 285) } texture { Green } translate <4.0, 1.1, -2.2> }
sphere { <4.0, 1.1, -2.2>, 0.55 texture { Gold } }
// drilled plate: a rounded slab minus a 6 x 2 grid of holes
difference {
  object { Round_Box_Union(<-1.6, 0, -0.5>, <1.6, 0.24, 0.5>, 0.08) }
  #for (K, 0, 1)
    #for (I, 0, 5)
      cylinder { <(I - 2.5) * 0.5, -1, (K - 0.5) * 0.5>, <(I - 2.5) * 0.5, 1, (K - 0.5) * 0.5>, 0.15 }
    #end
  #end
  texture { Ivory } Turn(y, -8) translate <-1.7, 0, 2.9>
}
union {
  cone { <0, 0, 0>, 0.55, <0, 1.6, 0>, 0 }
  sphere { <0, 1.5, 0>, 0.3 }
  texture { Blue } translate <5.9, 0, 0.2>
}
object { Trefoil texture { Teal } scale 0.4 Turn(y, -12) translate <-1.6, 1.28, -3.9> }
torus { 0.56, 0.17 texture { Gold } Turn(x, 90) Turn(y, -35) translate <1.1, 0.73, 3.5> }
