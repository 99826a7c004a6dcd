// data/scenes/part_objects.json for POV-Ray 3.7. POV-Ray has no part objects: each is its
// full surface clipped by half-spaces (clipped_by), which is how POV-Ray users build them.
#include "common.inc"
Camera(<0, 5.2, 10.5>, <0, 0.8, 0>, 40)
PointLight(<5, 9, 9>, <170, 165, 150>)
DirectionalLight(<-0.4, -1, -0.5>, <0.45, 0.5, 0.6>)
#declare Floor = texture { Albedo(0.6, 0.6, 0.62) }
#declare Orange = texture { Albedo(0.85, 0.42, 0.12) }
#declare Teal = texture { Albedo(0.12, 0.55, 0.58) }
#declare Plum = texture { Albedo(0.5, 0.2, 0.55) }
#declare Sand = texture { Albedo(0.85, 0.75, 0.5) }
#declare White = texture { Albedo(0.88, 0.88, 0.86) }

plane { y, 0 texture { Floor } }
// dome: theta 0..90 (on a sphere, a polar range is a height range: y = r cos theta)
sphere { 0, 1 clipped_by { plane { -y, 0 } } texture { Orange } translate <-4.2, 0, 0> }
// band: theta 40..140
sphere { 0, 1 clipped_by { intersection { plane { y, cos(radians(40)) }
                                          plane { -y, -cos(radians(140)) } } }
         texture { Teal } translate <-1.6, 1, -0.6> }
// open shell: phi 60..330, theta 25..180
sphere { 0, 1 clipped_by { intersection { PhiWedge(60, 330) plane { y, cos(radians(25)) } } }
         texture { Plum } translate <1.2, 1, -0.9> }
// open tub: part cylinder and annulus, phi 200..520
union {
  cylinder { <0, 0, 0>, <0, 1.2, 0>, 0.8 open clipped_by { PhiWedge(200, 520) } }
  disc { <0, 0, 0>, y, 0.8 clipped_by { PhiWedge(200, 520) } }
  texture { Sand } translate <4.0, 0, -0.2>
}
// half pipe: phi 180..360, lying along x
cylinder { <0, -1.3, 0>, <0, 1.3, 0>, 0.6 open clipped_by { PhiWedge(180, 360) }
           texture { White } Turn(z, 90) translate <-0.2, 0.6, 2.2> }
// three-quarter ring: phi 0..270
disc { <0, 0, 0>, y, 1.0, 0.35 clipped_by { PhiWedge(0, 270) } texture { Orange }
       translate <2.4, 0.01, 2.3> }
// pie slices: four annuli facing +z, phi 30..330
#declare Slices = array[3] { Teal, Plum, Sand }
#for (I, 0, 3)
  disc { <0, 0, 0>, y, 0.38 clipped_by { PhiWedge(30, 330) } Turn(x, 90)
         texture { Slices[mod(I, 3)] } translate <(I - 1.5) * 0.9 - 3.3, 0.39, 2.6> }
#end
// arch: part torus, phi 270..450, tube angle 90..360 (the quarter of the tube that is outside
// the ring's circle and above its plane is cut away)
torus { 0.9, 0.22
        clipped_by { intersection { PhiWedge(270, 450)
                                    union { plane { y, 0 } cylinder { -y, y, 0.9 } } } }
        texture { Teal } Turn(x, -90) Turn(y, 25) translate <-4.6, 0, -2.4> }
// cup: theta 90..180
sphere { 0, 0.6 clipped_by { plane { y, 0 } } texture { White } translate <4.3, 0.6, 2.0> }
