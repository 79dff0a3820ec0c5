#!/bin/sh
# Writes small OBJ meshes into DIR as a seed corpus for fuzz_obj:
#   fuzz/seeds/obj.sh DIR
# A tetrahedron, a cube of quads with normals and texture coordinates in two
# objects, a concave polygon with relative indices, and the lines a cut mesh
# ignores (materials, groups, smoothing, tags, lines, points).
set -e
dir=${1:?usage: obj.sh DIR}
mkdir -p "$dir"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n' > "$dir/tetra.obj"
printf '# cube\nmtllib c.mtl\no a\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl m\ns 1\nf 1/1/1 4/2/1 3/3/1 2/1/1\nf 5/1/1 6/2/1 7/3/1 8/1/1\ng side\nf 1//1 2//1 6//1 5//1\no b\nf 2/1 3/2 7/3 6/1\nf 3 4 8 7\nf 4 1 5 8\n' > "$dir/cube.obj"
printf 'v 2 1 5\r\nv 1 1 5\r\nv 1 2 5\r\nv 0 2 5\r\nv 0 0 5\r\nv 2 0 5\r\nf -6 -5 -4 -3 -2 -1\r\n' > "$dir/concave.obj"
printf 'v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nl 1 2\np 3\nt crease 2/1/0 1 2 3.5\nvw 1 0 0.5\nf 1 2 3\n' > "$dir/extras.obj"
