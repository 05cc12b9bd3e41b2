// CGAL Mesh_3 as an anchor for scripts/compare.py and scripts/compare_images.py: a labelled image
// or a closed polyhedral surface (features protected) meshed with the criteria given on the
// command line, perturbation and exudation on (CGAL's defaults), written as Medit .mesh.
//
//   mesh3 image  LABELS.raw NX NY NZ VX VY VZ OUT.mesh FACET_SIZE FACET_DISTANCE CELL_SIZE
//                (LABELS.raw: NX*NY*NZ little-endian uint16, x fastest)
//   mesh3 surface IN.off OUT.mesh EDGE_SIZE FACET_SIZE FACET_DISTANCE CELL_SIZE
//
// Prints one JSON line: {"seconds": meshing alone, "vertices": n, "cells": n}.
// Build: g++ -O2 -DNDEBUG -std=c++17 mesh3.cpp -o mesh3 -lgmp -lmpfr (libcgal-dev).

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/make_mesh_3.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
namespace params = CGAL::parameters;

template <class C3t3>
static int finish(const C3t3& c3t3, const char* out, double seconds) {
  std::ofstream os(out);
  // No rebinding: the subdomain index (the image label) is written as the tet reference.
  c3t3.output_to_medit(os, false);
  if (!os) {
    std::cerr << "cannot write " << out << "\n";
    return 2;
  }
  std::cout << "{\"seconds\": " << seconds << ", \"vertices\": " << c3t3.triangulation().number_of_vertices()
            << ", \"cells\": " << c3t3.number_of_cells_in_complex() << "}" << std::endl;
  return 0;
}

static int image(int argc, char** argv) {
  if (argc != 13) {
    std::cerr << "usage: mesh3 image LABELS.raw NX NY NZ VX VY VZ OUT.mesh FACET_SIZE FACET_DISTANCE CELL_SIZE\n";
    return 2;
  }
  const std::size_t nx = std::atol(argv[3]), ny = std::atol(argv[4]), nz = std::atol(argv[5]);
  const double vx = std::atof(argv[6]), vy = std::atof(argv[7]), vz = std::atof(argv[8]);
  const double fs = std::atof(argv[10]), fd = std::atof(argv[11]), cs = std::atof(argv[12]);
  std::vector<std::uint16_t> buf(nx * ny * nz);
  std::ifstream in(argv[2], std::ios::binary);
  in.read(reinterpret_cast<char*>(buf.data()), buf.size() * 2);
  if (!in) {
    std::cerr << argv[2] << ": expected " << buf.size() * 2 << " bytes\n";
    return 2;
  }
  _image* im = _createImage(nx, ny, nz, 1, vx, vy, vz, 2, WK_FIXED, SGN_UNSIGNED);
  std::memcpy(im->data, buf.data(), buf.size() * 2);
  CGAL::Image_3 img(im);

  typedef CGAL::Labeled_mesh_domain_3<K> Domain;
  typedef CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type Tr;
  typedef CGAL::Mesh_complex_3_in_triangulation_3<Tr> C3t3;
  typedef CGAL::Mesh_criteria_3<Tr> Criteria;
  auto t0 = std::chrono::steady_clock::now();
  Domain domain = Domain::create_labeled_image_mesh_domain(img);
  Criteria criteria(params::facet_angle = 30, params::facet_size = fs, params::facet_distance = fd,
                    params::cell_radius_edge_ratio = 3, params::cell_size = cs);
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::perturb(), params::exude());
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return finish(c3t3, argv[9], s);
}

static int surface(int argc, char** argv) {
  if (argc != 8) {
    std::cerr << "usage: mesh3 surface IN.off OUT.mesh EDGE_SIZE FACET_SIZE FACET_DISTANCE CELL_SIZE\n";
    return 2;
  }
  typedef CGAL::Mesh_polyhedron_3<K>::type Polyhedron;
  typedef CGAL::Polyhedral_mesh_domain_with_features_3<K> Domain;
  typedef CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type Tr;
  typedef CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index> C3t3;
  typedef CGAL::Mesh_criteria_3<Tr> Criteria;
  Polyhedron poly;
  std::ifstream in(argv[2]);
  if (!(in >> poly) || poly.empty() || !poly.is_closed()) {
    std::cerr << argv[2] << ": not a closed OFF polyhedron\n";
    return 2;
  }
  const double es = std::atof(argv[4]), fs = std::atof(argv[5]), fd = std::atof(argv[6]), cs = std::atof(argv[7]);
  auto t0 = std::chrono::steady_clock::now();
  Domain domain(poly);
  domain.detect_features();
  Criteria criteria(params::edge_size = es, params::facet_angle = 25, params::facet_size = fs,
                    params::facet_distance = fd, params::cell_radius_edge_ratio = 3, params::cell_size = cs);
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::perturb(), params::exude());
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return finish(c3t3, argv[3], s);
}

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "image") return image(argc, argv);
  if (argc > 1 && std::string(argv[1]) == "surface") return surface(argc, argv);
  std::cerr << "usage: mesh3 image ... | mesh3 surface ... (see the source)\n";
  return 2;
}
