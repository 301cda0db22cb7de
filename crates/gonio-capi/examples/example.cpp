// gonio C++ example: the RAII wrapper gonio.hpp over gonio.h. Reads a photometric file, samples
// it with the HDS mapping from four threads sharing one sampler, and checks pdf(sample(u)) ==
// pdf and invert(sample(u)) == u; then checks that errors arrive as gonio::Error, and samples a
// constant-sky environment map (gonio::EnvMap) built in memory.
//
// Build (one line): c++ -std=c++17 -Wall -Wextra -I crates/gonio-capi/include example.cpp
//                   target/release/libgonio_capi.a -lpthread -ldl -lm -o example_cpp
// Run:   ./example_cpp FILE.ies          exit status 0 when every check passes.
#include "gonio.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <thread>

int main(int argc, char **argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s FILE.ies|FILE.ldt\n", argv[0]);
        return 2;
    }
    int failures = 0;
    try {
        gonio::Diagram diagram = gonio::Diagram::read(argv[1]);
        std::printf("%s: flux %.6g lm, %zu warnings\n", argv[1], diagram.flux(),
                    diagram.warnings().size());
        const gonio::Sampler sampler = diagram.build(GONIO_METHOD_HDS, GONIO_DOMAIN_AUTO);

        // Four threads share the sampler; each checks its own points (fixed seeds).
        const int threads = 4, per_thread = 1000;
        std::vector<double> worst_pdf(threads, 0.0), worst_uv(threads, 0.0);
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; t++)
            pool.emplace_back([&, t] {
                std::mt19937_64 rng(1234 + t);
                std::uniform_real_distribution<double> unit(0.0, 1.0);
                for (int i = 0; i < per_thread; i++) {
                    const double u = unit(rng), v = unit(rng);
                    const gonio::Sample s = sampler.sample(u, v);
                    const double p = sampler.pdf(s.direction);
                    worst_pdf[t] = std::max(worst_pdf[t], std::fabs(p - s.pdf) / (s.pdf > 0 ? s.pdf : 1.0));
                    if (s.pdf > 0) {
                        const auto uv = sampler.invert(s.direction);
                        const double e = std::max(std::fabs(uv[0] - u), std::fabs(uv[1] - v));
                        if (!(e <= worst_uv[t])) worst_uv[t] = e;
                    }
                }
            });
        for (auto &th : pool) th.join();
        const double wp = *std::max_element(worst_pdf.begin(), worst_pdf.end());
        const double wu = *std::max_element(worst_uv.begin(), worst_uv.end());
        std::printf("  %s, %d threads x %d points: pdf(sample(u)) rel. error %.1e, round trip %.1e\n",
                    sampler.method().c_str(), threads, per_thread, wp, wu);
        if (!(wp <= 1e-9)) failures++;
        if (!(wu <= 1e-8)) failures++;

        // The batch agrees with one point at a time.
        std::vector<double> uv = {0.25, 0.75, 0.5, 0.125}, pdfs;
        const std::vector<double> dirs = sampler.sample_batch(uv, pdfs);
        const gonio::Sample one = sampler.sample(0.5, 0.125);
        // Up to round-off: the library's batch path may use SIMD and FMA.
        if (!(std::fabs(dirs[3] - one.direction[0]) <= 1e-14) ||
            !(std::fabs(pdfs[1] - one.pdf) <= 1e-13 * one.pdf))
            failures++;

        // An odd number of values (half a point at the end) is an error, not dropped; so is a
        // NaN point (issue 25).
        try {
            std::vector<double> odd = {0.25, 0.75, 0.5}, p;
            sampler.sample_batch(odd, p);
            failures++;
        } catch (const gonio::Error &e) {
            if (e.status() != GONIO_ERR_INVALID_ARGUMENT) failures++;
            std::printf("expected error: %s\n", e.what());
        }
        try {
            sampler.sample(std::nan(""), 0.5);
            failures++;
        } catch (const gonio::Error &e) {
            if (e.status() != GONIO_ERR_INVALID_ARGUMENT) failures++;
            std::printf("expected error: %s\n", e.what());
        }
    } catch (const gonio::Error &e) {
        std::fprintf(stderr, "unexpected error %d: %s\n", (int)e.status(), e.what());
        return 1;
    }

    // Errors are exceptions with the library's message.
    try {
        gonio::Diagram::read("/nonexistent/lamp.ldt");
        failures++;
    } catch (const gonio::Error &e) {
        if (e.status() != GONIO_ERR_IO) failures++;
        std::printf("expected error: %s\n", e.what());
    }
    try {
        const std::string text = "not a EULUMDAT file";
        gonio::Diagram::read_memory(std::vector<std::uint8_t>(text.begin(), text.end()),
                                    GONIO_FORMAT_EULUMDAT, "bad.ldt");
        failures++;
    } catch (const gonio::Error &e) {
        if (e.status() != GONIO_ERR_PARSE || std::string(e.what()).rfind("bad.ldt:", 0) != 0)
            failures++;
        std::printf("expected error: %s\n", e.what());
    }
    // An environment map (a constant sky as a PFM built in memory): uniform density 1/(4 pi),
    // round trips, and an all-black sky refused with GONIO_ERR_BUILD.
    for (float level : {1.5f, 0.0f}) {
        std::string head = "PF\n8 4\n-1.0\n";
        std::vector<std::uint8_t> pfm(head.begin(), head.end());
        std::uint32_t bits;
        std::memcpy(&bits, &level, sizeof bits);
        for (int i = 0; i < 8 * 4 * 3; i++)
            for (int k = 0; k < 4; k++) pfm.push_back(std::uint8_t(bits >> (8 * k)));
        try {
            const gonio::EnvMap env = gonio::EnvMap::read_memory(pfm, "sky.pfm");
            const double uniform = 1.0 / (4.0 * M_PI);
            double worst = 0.0;
            for (int i = 0; i < 100; i++) {
                // v away from 0 and 1: at a pole every u maps to the same direction.
                const double u = (i + 0.5) / 100.0;
                const double v = 0.005 + 0.99 * std::fmod(0.37 * i, 1.0);
                const gonio::EnvSample s = env.sample(u, v);
                const std::array<double, 2> back = env.invert(s.direction);
                worst = std::max({worst, std::fabs(s.pdf - uniform),
                                  std::fabs(env.pdf(s.direction) - uniform),
                                  std::fabs(back[0] - u), std::fabs(back[1] - v)});
                if (s.rgb[0] != level || env.eval(s.direction)[2] != level) failures++;
            }
            if (level == 0.0f || worst > 1e-9) failures++;
            std::printf("environment map: constant sky, 100 samples, max |error| %.1e\n", worst);
            // Options: bilinear lookup and constant custom weights (the uniform density).
            GonioEnvOptions o = gonio::EnvMap::default_options();
            std::vector<float> cw(8 * 4, 2.0f);
            o.lookup = GONIO_ENV_LOOKUP_BILINEAR;
            o.weight = GONIO_ENV_WEIGHT_CUSTOM;
            o.custom_weights = cw.data();
            o.custom_len = cw.size();
            const gonio::EnvMap opt = gonio::EnvMap::read_memory(pfm, o, "sky.pfm");
            const gonio::EnvSample s = opt.sample(0.3, 0.7);
            if (std::fabs(s.pdf - uniform) > 1e-12 || opt.eval({0.3, -0.2, 0.9})[1] != level ||
                !opt.warnings().empty() || !env.warnings().empty())
                failures++;
            std::printf("environment map with options (bilinear, custom weights): pdf %.6g\n",
                        s.pdf);
            // The float32 environment map: the uniform density to float round-off.
            const gonio::EnvMapF32 f32 =
                gonio::EnvMapF32::from(gonio::EnvMap::read_memory(pfm, "sky.pfm"));
            std::vector<float> u32, v32, x, y, z, p32, rgb;
            for (int i = 0; i < 50; i++) {
                u32.push_back(float((i + 0.5) / 50.0));
                v32.push_back(float(std::fmod(0.618034 * (i + 0.5), 1.0)));
            }
            f32.sample(u32, v32, x, y, z, p32, rgb);
            const std::vector<float> q32 = f32.pdf(x, y, z);
            for (int i = 0; i < 50; i++)
                if (std::fabs(p32[i] - float(uniform)) > 5e-7 * uniform ||
                    std::fabs(q32[i] - float(uniform)) > 5e-7 * uniform || rgb[3 * i] != level)
                    failures++;
            std::printf("float32 environment map: %zu bytes, pdf %.9g\n", f32.memory_bytes(),
                        double(p32[0]));
        } catch (const gonio::Error &e) {
            if (level != 0.0f || e.status() != GONIO_ERR_BUILD) failures++;
            std::printf("expected error: %s\n", e.what());
        }
    }
    if (failures) {
        std::fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    std::printf("C++ example: all checks passed\n");
    return 0;
}
