#include "solver/exact_solver.h"

#include <omp.h>

#include <Eigen/Dense>
#include <chrono>
#include <fmt/format.h>

#include "engine/compensated_sum.h"
#include "engine/convex_scene.h"
#include "engine/error.h"
#include "engine/hierarchy.h"
#include "solver/closed_enclosure.h"
#include "visibility/exact_visibility.h"

namespace flatrad {

namespace {


struct Element {
    Segment seg;   // oriented lit-left
    int patch;
    int segment;   // scene segment number (blocker to skip)
    double t0, t1; // file-order parameters along the patch
    double length;
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }


}  // namespace

namespace {

// Both: K equal elements per patch where `mesh` is null, else its elements.
Solution solve(const Scene& scene, const ExactMesh* mesh, const ExactSolverOptions& options) {
    const auto t_start = Clock::now();
    const int K = mesh ? 0 : options.subdivide;
    if (mesh) {
        check_mesh(scene, *mesh);
        check_exact_solver_memory(scene, *mesh);
    } else {
        if (K < 1) throw InputError(scene.file, "--subdivide", fmt::format("expected an integer >= 1, found {}", K));
        check_exact_solver_memory(scene, K);
    }
    const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
    const int C = scene.channels;

    // 1. Elements: K equal pieces of each patch, along its lit-left
    //    orientation, or the mesh's.
    std::vector<Element> elems;
    elems.reserve(mesh ? static_cast<size_t>(mesh->elements()) : scene.patches.size() * static_cast<size_t>(K));
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        const Patch& patch = scene.patches[p];
        const Segment o = scene.patch_segment(static_cast<int>(p));
        if (mesh) {
            // Cuts in file order t; along the oriented segment s = t for a
            // left-lit patch, 1 - t for a right-lit one.
            const std::vector<double>& cuts = mesh->cuts[p];
            const size_t m = cuts.size() + 1;
            for (size_t k = 0; k < m; ++k) {
                Element e;
                e.t0 = k == 0 ? 0.0 : cuts[k - 1];
                e.t1 = k + 1 == m ? 1.0 : cuts[k];
                const double s0 = patch.lit_left ? e.t0 : 1 - e.t1, s1 = patch.lit_left ? e.t1 : 1 - e.t0;
                e.seg = {s0 == 0 ? o.a : lerp(o.a, o.b, s0), s1 == 1 ? o.b : lerp(o.a, o.b, s1)};
                e.patch = static_cast<int>(p);
                e.segment = patch.segment;
                e.length = patch.length * (e.t1 - e.t0);
                elems.push_back(e);
            }
            continue;
        }
        for (int k = 0; k < K; ++k) {
            const double s0 = static_cast<double>(k) / K, s1 = static_cast<double>(k + 1) / K;
            Element e;
            e.seg = {k == 0 ? o.a : lerp(o.a, o.b, s0), k + 1 == K ? o.b : lerp(o.a, o.b, s1)};
            e.patch = static_cast<int>(p);
            e.segment = patch.segment;
            // The oriented segment runs against the file order for a right-lit patch.
            e.t0 = patch.lit_left ? s0 : 1 - s1;
            e.t1 = patch.lit_left ? s1 : 1 - s0;
            e.length = patch.length / K;
            elems.push_back(e);
        }
    }
    const int n = static_cast<int>(elems.size());

    // Unlit sides absorb everything they receive (SPEC): they are sinks.
    std::vector<std::pair<Segment, int>> sinks;
    for (size_t s = 0; s < scene.segments.size(); ++s) {
        const SceneSegment& ss = scene.segments[s];
        if (!ss.lit_left) sinks.push_back({ss.seg, static_cast<int>(s)});
        if (!ss.lit_right) sinks.push_back({ss.seg.reversed(), static_cast<int>(s)});
    }

    // 2. Form factors, both cores: F(a, b) for every element pair, and the
    //    fraction of each element's light that lands on unlit sides.
    const auto t_ff = Clock::now();
    Hierarchy hierarchy(scene.segment_geometry());
    hierarchy.set_blockers(possible_blockers(scene));  // hull walls block nothing (engine/convex_scene.h)
    const ExactVisibility visibility(hierarchy);
    Eigen::MatrixXd F = Eigen::MatrixXd::Zero(n, n);
    std::vector<double> to_sinks(static_cast<size_t>(n), 0.0);
    VisibilityStats vis;
    long links = 0;
#pragma omp parallel num_threads(threads) reduction(+ : links)
    {
        ExactWorkspace ws;
        VisibilityStats local;
#pragma omp for schedule(dynamic, 1)
        for (int a = 0; a < n; ++a) {
            const Element& ea = elems[static_cast<size_t>(a)];
            for (int b = a + 1; b < n; ++b) {
                const Element& eb = elems[static_cast<size_t>(b)];
                if (ea.segment == eb.segment) continue;  // collinear: no exchange
                const double X = visibility.exchange(ea.seg, eb.seg, ea.segment, eb.segment, ws, local);
                if (X == 0) continue;
                F(a, b) = X / ea.length;  // reciprocity: L_a F_ab = L_b F_ba = X
                F(b, a) = X / eb.length;
                links += 2;
            }
            CompensatedSum sunk;
            for (const auto& [seg, s] : sinks) {
                if (s == ea.segment) continue;
                sunk.add(visibility.exchange(ea.seg, seg, ea.segment, s, ws, local));
            }
            to_sinks[static_cast<size_t>(a)] = sunk.value() / ea.length;
        }
#pragma omp critical
        vis += local;
    }
    const double ff_time = seconds_since(t_ff);

    // 3. Refuse a system without a unique solution, then solve each channel
    //    directly: (I - rho F) B = E.
    const auto t_solve = Clock::now();
    Eigen::MatrixXd B(n, C);
    double residual = 0;
    std::vector<double> rho_prev;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;
    for (int c = 0; c < C; ++c) {
        std::vector<double> rho(static_cast<size_t>(n));
        Eigen::VectorXd E(n);
        for (int a = 0; a < n; ++a) {
            const Material& m = scene.materials[static_cast<size_t>(scene.patches[static_cast<size_t>(elems[static_cast<size_t>(a)].patch)].material)];
            rho[static_cast<size_t>(a)] = m.reflectance[static_cast<size_t>(c)];
            E(a) = m.emission[static_cast<size_t>(c)];
        }
        const std::vector<int> closed = closed_white_set(F, rho);
        if (!closed.empty()) {
            std::vector<int> patches;
            for (int a : closed) patches.push_back(elems[static_cast<size_t>(a)].patch);
            refuse_closed_white(scene, patches, c);
        }
        Eigen::MatrixXd A = -F;
        for (int a = 0; a < n; ++a) {
            A.row(a) *= rho[static_cast<size_t>(a)];
            A(a, a) += 1;
        }
        if (rho != rho_prev) {
            lu.compute(A);
            rho_prev = rho;
        }
        B.col(c) = lu.solve(E);
        const double scale = std::max(E.cwiseAbs().maxCoeff(), B.col(c).cwiseAbs().maxCoeff());
        if (scale > 0) residual = std::max(residual, (A * B.col(c) - E).cwiseAbs().maxCoeff() / scale);
    }
    const double solve_time = seconds_since(t_solve);
    const auto t_result = Clock::now();

    // 4. Results per patch (SPEC order) and totals.
    Solution sol;
    sol.method = "exact";
    sol.subdivide = K;
    sol.channels = C;
    sol.patches.resize(scene.patches.size());
    for (int a = 0; a < n; ++a) {
        const Element& e = elems[static_cast<size_t>(a)];
        ElementValue v;
        v.t0 = e.t0;
        v.t1 = e.t1;
        v.B.resize(static_cast<size_t>(C));
        for (int c = 0; c < C; ++c) v.B[static_cast<size_t>(c)] = B(a, c);
        sol.patches[static_cast<size_t>(e.patch)].elements.push_back(std::move(v));
    }
    for (PatchResult& pr : sol.patches) {
        std::sort(pr.elements.begin(), pr.elements.end(),
                  [](const ElementValue& x, const ElementValue& y) { return x.t0 < y.t0; });
        pr.radiosity.assign(static_cast<size_t>(C), 0.0);
        for (int c = 0; c < C; ++c) {
            CompensatedSum s;
            if (mesh) {
                // Elements of different lengths: weighted by their share of the patch.
                for (const ElementValue& v : pr.elements) s.add((v.t1 - v.t0) * v.B[static_cast<size_t>(c)]);
                pr.radiosity[static_cast<size_t>(c)] = s.value();
            } else {
                for (const ElementValue& v : pr.elements) s.add(v.B[static_cast<size_t>(c)]);
                pr.radiosity[static_cast<size_t>(c)] = s.value() / static_cast<double>(pr.elements.size());
            }
        }
    }
    const Eigen::MatrixXd H = F * B;  // irradiance on each element
    for (int c = 0; c < C; ++c) {
        CompensatedSum emitted, absorbed, escaped;
        for (int a = 0; a < n; ++a) {
            const Element& e = elems[static_cast<size_t>(a)];
            const Material& m = scene.materials[static_cast<size_t>(scene.patches[static_cast<size_t>(e.patch)].material)];
            const double rho = m.reflectance[static_cast<size_t>(c)];
            emitted.add(e.length * m.emission[static_cast<size_t>(c)]);
            absorbed.add(e.length * (1 - rho) * H(a, c));
            absorbed.add(e.length * B(a, c) * to_sinks[static_cast<size_t>(a)]);
            CompensatedSum row;
            row.add(1);
            for (int b = 0; b < n; ++b) row.add(-F(a, b));
            row.add(-to_sinks[static_cast<size_t>(a)]);
            escaped.add(e.length * B(a, c) * row.value());
        }
        sol.totals.add_channel(emitted.value(), absorbed.value(), escaped.value());
    }

    sol.stats.form_factor_time_s = ff_time;
    sol.stats.linear_solve_time_s = solve_time;
    sol.stats.elements = n;
    sol.stats.links = links;
    sol.stats.iterations = 0;
    sol.stats.residual = residual;
    sol.stats.threads = threads;
    sol.stats.visibility = vis;
    // (The form factors' stage includes the mesh and the visibility set-up.)
    const double result_time = seconds_since(t_result);
    sol.stats.phases = {{"form factors", std::chrono::duration<double>(t_solve - t_start).count()},
                        {"solve", solve_time},
                        {"result", result_time}};
    sol.stats.time_s = seconds_since(t_start);
    return sol;
}

}  // namespace

Solution solve_exact(const Scene& scene, const ExactSolverOptions& options) { return solve(scene, nullptr, options); }

Solution solve_exact(const Scene& scene, const ExactMesh& mesh, const ExactSolverOptions& options) {
    return solve(scene, &mesh, options);
}

}  // namespace flatrad
