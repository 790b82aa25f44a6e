// Embedding flatrad: build a scene in code, solve it exactly, print the
// radiosity of every patch. With a scene file as argument, solve that too.
// Uses only the public header <flatrad/flatrad.h> (README, "Embedding").
//
//   flatrad_embed_example [SCENE.json]
//
// Exit status: 0 done, 2 bad input (one line `error: ...` on stderr), 1 other.
#include <cstdio>
#include <exception>
#include <string>

#include <flatrad/flatrad.h>

namespace api = flatrad::api;

namespace {

void print_result(const api::Scene& scene, const api::Result& result) {
    std::printf("scene \"%s\": %zu patches, %d channel(s), %s solve in %.3f s, residual %.1e\n",
                scene.name().c_str(), result.patch_count(), result.channels, result.method.c_str(),
                result.time_s, result.residual);
    for (std::size_t p = 0; p < result.patch_count(); ++p) {
        const api::PatchRadiosity& patch = result.patches[p];
        std::printf("  %3zu %-8s seg %2d %-5s (%6.3f, %6.3f)-(%6.3f, %6.3f) B =", p, patch.surface.c_str(),
                    patch.segment, api::side_name(patch.side), patch.a.x, patch.a.y, patch.b.x, patch.b.y);
        for (double b : patch.radiosity) std::printf(" %.6f", b);
        std::printf("\n");
    }
    for (int c = 0; c < result.channels; ++c) {
        const auto k = static_cast<std::size_t>(c);
        std::printf("  channel %d: emitted %.6f absorbed %.6f escaped %.3g balance %.3g\n", c,
                    result.emitted[k], result.absorbed[k], result.escaped[k], result.balance[k]);
    }
}

/// A closed 4 x 3 box (grey, lit inside), a lamp under its ceiling shining
/// down, and a two-sided blocker plate between the lamp and the floor.
api::Scene box_with_lamp_and_blocker() {
    api::SceneBuilder builder("box with a lamp and a blocker", "<embed_example>");
    builder.add_material("grey", {0.6})
        .add_material("lamp", {0.0}, {10.0})
        .add_material("dark", {0.2})
        .add_polygon("box", "grey", {{0, 0}, {4, 0}, {4, 3}, {0, 3}}, api::Side::In)
        // Right of the direction of travel (+x) is below: the lamp shines down.
        .add_polyline("lamp", "lamp", {{1.5, 2.9}, {2.5, 2.9}}, api::Side::Right)
        .add_polyline("blocker", "dark", {{1.6, 1.5}, {2.4, 1.5}}, api::Side::Both);
    return builder.build();
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const api::Scene box = box_with_lamp_and_blocker();
        api::SolveOptions options;
        options.method = api::Method::Exact;
        options.subdivide = 2;
        print_result(box, api::solve(box, options));

        const double F = api::form_factor(box, {"lamp"}, {"box"});
        std::printf("form factor lamp -> box (exact visibility): %.6f\n", F);

        if (argc > 1) {
            const api::Scene scene = api::load_scene(argv[1]);
            print_result(scene, api::solve(scene));
        }
        std::printf("flatrad %s: done\n", api::version());
        return 0;
    } catch (const api::InputError& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
