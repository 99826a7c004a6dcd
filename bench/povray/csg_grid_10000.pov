// data/scenes/csg_grid_10000.json for POV-Ray 3.7: 10,000 balls with a cube bitten out.
#include "common.inc"
Camera(<0, 38, 66>, <0, 0, 4>, 44)
PointLight(<-30, 60, 60>, <7000, 6600, 6000>)
DirectionalLight(<0.6, -1, -0.4>, <0.45, 0.5, 0.6>)
plane { y, 0 Albedo(0.5, 0.5, 0.52) }
#declare Colours = array[7] {
  <0.78, 0.2, 0.15>, <0.85, 0.65, 0.22>, <0.15, 0.55, 0.55>, <0.88, 0.85, 0.78>,
  <0.85, 0.65, 0.22>, <0.78, 0.2, 0.15>, <0.15, 0.55, 0.55> }
#declare BittenBall = difference {
  sphere { <0, 0.42, 0>, 0.42 }
  box { <-0.12, 0.48, -0.12>, <0.6, 1.0, 0.6> }
}
#for (K, 0, 99)
  #for (I, 0, 99)
    object { BittenBall translate <I - 49.5, 0, K - 49.5>
             pigment { rgb Colours[mod(K * 100 + I, 7)] / pi } }
  #end
#end
