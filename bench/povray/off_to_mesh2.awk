# Writes an OFF file of triangles as a POV-Ray mesh2 named Trefoil (scripts/compare-povray).
# Comments and blank lines are skipped; faces must be triangles (the shipped mesh's are).
/^[ \t]*#/ || NF == 0 { next }
state == 0 { state = 1; next }                      # the "OFF" line
state == 1 { vertices = $1; faces = $2; state = 2; read = 0
             print "#declare Trefoil = mesh2 {\n  vertex_vectors { " vertices; next }
state == 2 { printf "    , <%s, %s, %s>\n", $1, $2, $3; if (++read == vertices) {
               print "  }\n  face_indices { " faces; state = 3; read = 0 }; next }
state == 3 { if ($1 != 3) { print "off_to_mesh2: face " read " is not a triangle" > "/dev/stderr"; exit 1 }
             printf "    , <%s, %s, %s>\n", $2, $3, $4; if (++read == faces) { print "  }\n}"; state = 4 } }
