// SPDX-License-Identifier: MIT
// Test helper for tests/output/test_pvtu.py: distributes a 5 x 3 rectangle with a curved top over
// the processes of the run (comm::world(): run it under mpirun, or alone for one process),
// refines it `refinements` times and writes the finest level with write_distributed_vtu, with
// fields that have closed forms: f = x + 2 y, u = (x y, x - y), the global vertex number, and
// per triangle the owning rank and the area.
// Usage: write_pvtu OUT.pvtu REFINEMENTS [ascii]
#include "comm/world.hpp"
#include "mesh/distributed.hpp"

#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
    using namespace mlc;
    if (argc < 3) {
        std::cerr << "usage: write_pvtu OUT.pvtu REFINEMENTS [ascii]\n";
        return 1;
    }
    try {
        const Communicator& comm = comm::world();
        mesh::Mesh m =
            mesh::structured_rectangle({0, 0}, {1, 0.6}, 5, 3, mesh::Diagonal::alternate);
        m.shapes.push_back({{0.5, -10.0}, 10.6});
        for (auto& e : m.boundary)
            if (e.tag == m.tag("top")) e.shape = 0;
        const auto H = mesh::distribute(m, std::atoi(argv[2]), comm);
        const mesh::LocalLevel& L = H.levels.back();
        const size_t nv = static_cast<size_t>(L.mesh.n_vertices());
        const size_t nt = static_cast<size_t>(L.mesh.n_cells());
        mesh::Field f{"f", 1, std::vector<double>(nv)}, u{"u", 2, std::vector<double>(2 * nv)},
            g{"global_vertex", 1, std::vector<double>(nv)};
        for (size_t v = 0; v < nv; ++v) {
            const Vec2& x = L.mesh.vertices[v];
            f.values[v] = x.x() + 2 * x.y();
            u.values[2 * v] = x.x() * x.y();
            u.values[2 * v + 1] = x.x() - x.y();
            g.values[v] = static_cast<double>(L.global_vertex[v]);
        }
        mesh::Field owner{"owner", 1, std::vector<double>(nt, comm.rank())};
        mesh::Field area{"area", 1, std::vector<double>(nt)};
        for (size_t t = 0; t < nt; ++t)
            area.values[t] = L.mesh.signed_measure(static_cast<int>(t));
        const bool ascii = argc > 3 && std::string(argv[3]) == "ascii";
        mesh::write_distributed_vtu(argv[1], L, {f, u, g}, {owner, area}, comm,
                                    ascii ? mesh::VtuFormat::ascii : mesh::VtuFormat::binary);
        if (comm.rank() == 0)
            std::cout << "wrote " << argv[1] << ": " << comm.size() << " pieces, "
                      << L.n_global_vertices << " vertices, " << L.n_global_triangles
                      << " triangles\n";
    } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
