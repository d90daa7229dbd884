// Second-order staggered (MAC) difference operators.
//
//   (D u)_{ijk} = (u_{i+1,j,k} - u_{ijk})/h + (v_{i,j+1,k} - v_{ijk})/h + (w_{i,j,k+1} - w_{ijk})/h
//   (G p)^x_{ijk} = (p_{ijk} - p_{i-1,j,k})/h, likewise in y and z       (G = -D^T)
//   (L u)_{ijk}   = sum_dir (u_{+} - 2 u + u_{-}) / h^2   per component
//
// Periodic directions wrap. In the square duct the wall-normal component is
// zero on the wall faces (its G entries there are zero, D uses the zero), and
// a tangential component half a cell from a wall uses the ghost value
// u_ghost = -u_first, so that the linear interpolant vanishes on the wall.
// Wall-face entries of every output are set to zero.
#pragma once

#include "full3d/grid.hpp"

namespace swim::full3d {

void divergence(const MacGrid& g, const VectorField& u, ScalarField& div);
/// max over the cells of |D u|, 1/s, without storing D u, the z planes split over `threads`
/// (a maximum: the same for any thread count). NaN when any velocity is not finite: every
/// face value enters the divergence of a cell next to it.
double max_abs_divergence(const MacGrid& g, const VectorField& u, int threads = 1);
void gradient(const MacGrid& g, const ScalarField& p, VectorField& grad);
void laplacian(const MacGrid& g, const VectorField& u, VectorField& lap);

/// Sets the wall-face entries (duct only) of u to zero.
void zero_wall_faces(const MacGrid& g, VectorField& u);

}  // namespace swim::full3d
