// gonio C++ example: the RAII wrapper gonio.hpp over gonio.h. Reads a photometric file, samples
// it with the HDS mapping from four threads sharing one sampler, and checks pdf(sample(u)) ==
// pdf and invert(sample(u)) == u; then checks that errors arrive as gonio::Error, and samples a
// constant-sky environment map (gonio::EnvMap) built in memory.
//
// Build (one line): c++ -std=c++17 -Wall -Wextra -I crates/gonio-capi/include example.cpp
//                   target/release/libgonio_capi.a -lpthread -ldl -lm -o example_cpp
// Run:   ./example_cpp FILE.ies          exit status 0 when every check passes.
#include "gonio.hpp"
#include "gonio_device.h"

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

        // Every batch form, both layouts and both precisions, against one point at a time, and
        // the rest of the sampler's calls (gonio.hpp covers the whole C ABI).
        {
            const std::vector<double> u = {0.25, 0.5, 0.9, 0.03}, v = {0.75, 0.125, 0.4, 0.97};
            const std::size_t n = u.size();
            std::vector<double> uvi, x(n), y(n), z(n), p(n), d(3 * n), p2(n), q(n), q2(n), t(n),
                t2(n), uvb(2 * n), ub(n), vb(n);
            for (std::size_t i = 0; i < n; i++) uvi.push_back(u[i]), uvi.push_back(v[i]);
            sampler.sample_batch_soa(u, v, x, y, z, p);
            sampler.sample_batch(gonio::span<const double>(uvi), d, p2);
            sampler.pdf_batch(d, q);
            sampler.pdf_batch_soa(x, y, z, q2);
            sampler.target_pdf_batch(d, t);
            sampler.target_pdf_batch_soa(x, y, z, t2);
            sampler.invert_batch(d, uvb);
            sampler.invert_batch_soa(x, y, z, ub, vb);
            std::vector<float> uf(u.begin(), u.end()), vf(v.begin(), v.end()), xf(n), yf(n), zf(n),
                pf(n), qf(n), uvf(2 * n), df(3 * n), pf2(n), tf(n), uf2(n), vf2(n), qf2(n), tf2(n),
                uvif(uvi.begin(), uvi.end());
            sampler.sample_batch_soa(gonio::span<const float>(uf), vf, xf, yf, zf, pf);
            sampler.sample_batch(gonio::span<const float>(uvif), df, pf2);
            sampler.pdf_batch(gonio::span<const float>(df), qf);
            sampler.pdf_batch_soa(gonio::span<const float>(xf), yf, zf, qf2);
            sampler.target_pdf_batch(gonio::span<const float>(df), tf);
            sampler.target_pdf_batch_soa(gonio::span<const float>(xf), yf, zf, tf2);
            sampler.invert_batch(gonio::span<const float>(df), uvf);
            sampler.invert_batch_soa(gonio::span<const float>(xf), yf, zf, uf2, vf2);
            double worst = 0.0, worst32 = 0.0;
            for (std::size_t i = 0; i < n; i++) {
                const gonio::Sample s = sampler.sample(u[i], v[i]);
                const double tp = sampler.target_pdf(s.direction);
                const auto back = sampler.invert(s.direction);
                worst = std::max({worst, std::fabs(x[i] - s.direction[0]),
                                  std::fabs(d[3 * i + 2] - s.direction[2]),
                                  std::fabs(p[i] - s.pdf) / s.pdf, std::fabs(p2[i] - s.pdf) / s.pdf,
                                  std::fabs(q[i] - s.pdf) / s.pdf, std::fabs(q2[i] - s.pdf) / s.pdf,
                                  std::fabs(t[i] - tp) / tp, std::fabs(t2[i] - tp) / tp,
                                  std::fabs(uvb[2 * i] - back[0]), std::fabs(vb[i] - back[1])});
                worst32 = std::max({worst32, std::fabs(xf[i] - s.direction[0]),
                                    std::fabs(df[3 * i + 1] - s.direction[1]),
                                    std::fabs(pf[i] - s.pdf) / s.pdf, double(std::fabs(pf2[i] - pf[i])),
                                    std::fabs(qf[i] - pf[i]) / s.pdf, std::fabs(qf2[i] - pf[i]) / s.pdf,
                                    std::fabs(tf[i] - tp) / tp, double(std::fabs(tf2[i] - tf[i])),
                                    std::fabs(uvf[2 * i] - u[i]), std::fabs(vf2[i] - v[i])});
            }
            const auto bound = sampler.ratio_bound();
            const std::vector<std::uint8_t> blob = sampler.tables(4, &diagram);
            GonioDeviceView view;
            const int e = gonio_device_view_init(&view, blob.data(), blob.size());
            std::printf("  every batch form: f64 max rel error %.1e, f32 %.1e; ratio bound [%.6f, "
                        "%.6f]; target power %.6g; domain %d; tables %zu bytes (device view %d)\n",
                        worst, worst32, bound ? bound->first : -1.0, bound ? bound->second : -1.0,
                        sampler.target_power(), (int)sampler.domain(), blob.size(), e);
            if (!(worst <= 1e-9) || !(worst32 <= 2e-4) || !bound || !(bound->first <= 1.0) ||
                !(bound->second >= 1.0) || e != GONIO_DEVICE_OK || sampler.tables(8).size() <= blob.size())
                failures++;
            // Mismatched sizes are errors before the C call.
            try {
                std::vector<double> short_out(n - 1);
                sampler.pdf_batch(d, short_out);
                failures++;
            } catch (const gonio::Error &err) {
                if (err.status() != GONIO_ERR_INVALID_ARGUMENT) failures++;
            }
            // The diagram's own calls and the build options.
            GonioBuildOptions o = gonio::Diagram::default_build_options();
            o.sphere_layout = GONIO_SPHERE_LAYOUT_LAMBERT;
            const gonio::Sampler lambert = diagram.build_with(GONIO_METHOD_HDS, GONIO_DOMAIN_AUTO, o);
            const gonio::Sample ls = lambert.sample(0.3, 0.6);
            if (!(std::fabs(lambert.pdf(ls.direction) - ls.pdf) <= 1e-9 * ls.pdf) ||
                !(diagram.max_intensity() >= diagram.intensity(ls.direction)) ||
                diagram.domain() != sampler.domain())
                failures++;
            std::printf("  gonio %s; photometry read limit %llu bytes\n", gonio::version().c_str(),
                        (unsigned long long)gonio::read_limit(GONIO_FILE_PHOTOMETRY));
            gonio::set_read_limit(GONIO_FILE_PHOTOMETRY, 0);
        }

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
            {
                // The float64 batches against single calls; the tables.
                const std::vector<double> uv = {0.2, 0.3, 0.7, 0.6};
                std::vector<double> dirs(6), pdf(2), pdf2(2), back(4);
                std::vector<float> rgb(6), rgb2(6);
                env.sample_batch(uv, dirs, pdf, rgb);
                env.pdf_batch(dirs, pdf2);
                env.invert_batch(dirs, back);
                env.eval_batch(dirs, rgb2);
                double e2 = 0.0;
                for (int i = 0; i < 2; i++) {
                    const gonio::Vec3 d = {dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]};
                    e2 = std::max({e2, std::fabs(pdf[i] - env.pdf(d)), std::fabs(pdf2[i] - pdf[i]),
                                   std::fabs(back[2 * i] - uv[2 * i]), std::fabs(back[2 * i + 1] - uv[2 * i + 1]),
                                   std::fabs(double(rgb2[3 * i] - env.eval(d)[0]))});
                }
                if (!(e2 <= 1e-9) || env.tables(4).size() < 256) failures++;
            }
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
            std::vector<float> iu(50), iv(50), c32(150);
            f32.invert(gonio::span<const float>(x), y, z, iu, iv);
            f32.eval(gonio::span<const float>(x), y, z, c32);
            for (int i = 0; i < 50; i++)
                if (std::fabs(iu[i] - u32[i]) > 1e-4f || c32[3 * i + 1] != level) failures++;
            std::printf("float32 environment map: %zu bytes, pdf %.9g\n", f32.memory_bytes(),
                        double(p32[0]));
        } catch (const gonio::Error &e) {
            if (level != 0.0f || e.status() != GONIO_ERR_BUILD) failures++;
            std::printf("expected error: %s\n", e.what());
        }
    }
    // A tabulated BRDF (a Lambertian JSON table in memory, albedo 0.5): gonio::Brdf and
    // gonio::BrdfSampler, single calls against the batches, and its family blob for the device.
    try {
        std::string js = "{\"format\": \"gonio-brdf\", \"version\": 1, \"symmetry\": \"isotropic\", "
                         "\"channels\": 1, \"theta_i_deg\": [0, 45, 90], \"phi_i_deg\": [0], "
                         "\"theta_o_deg\": [0, 30, 60, 90], \"phi_o_deg\": [0, 120, 240], \"values\": [";
        char value[32];
        std::snprintf(value, sizeof value, "%.17g", 0.5 / M_PI);
        for (int i = 0; i < 3 * 4 * 3; i++) js += (i ? ", " : "") + std::string(value);
        js += "]}";
        const gonio::Brdf brdf = gonio::Brdf::read_memory(std::vector<std::uint8_t>(js.begin(), js.end()),
                                                          "lambert.json");
        const GonioBrdfInfo info = brdf.info();
        const gonio::BrdfSampler bs = brdf.sampler();
        const gonio::Vec3 wi = {0.3, 0.1, 0.9486832980505138};
        const std::vector<double> uv = {0.2, 0.7, 0.6, 0.1}, wiv(wi.begin(), wi.end());
        std::vector<GonioBrdfSample> out(2);
        bs.sample_batch(wiv, uv, out);
        std::vector<double> wo, pdf(2), back(4), f(6);
        for (const GonioBrdfSample &s : out) wo.insert(wo.end(), s.direction, s.direction + 3);
        bs.pdf_batch(wiv, wo, pdf);
        bs.invert_batch(wiv, wo, back);
        brdf.eval_batch(wiv, wo, f);
        double worst = 0.0;
        for (int i = 0; i < 2; i++) {
            const GonioBrdfSample s = bs.sample(wi, uv[2 * i], uv[2 * i + 1]);
            const gonio::Vec3 d = {s.direction[0], s.direction[1], s.direction[2]};
            const auto b = bs.invert(wi, d);
            worst = std::max({worst, std::fabs(s.pdf - out[i].pdf), std::fabs(bs.pdf(wi, d) - pdf[i]),
                              std::fabs(b[0] - back[2 * i]), std::fabs(b[0] - uv[2 * i]),
                              std::fabs(brdf.eval(wi, d)[0] - f[3 * i]),
                              std::fabs(bs.eval(wi, d)[1] - 0.5 / M_PI),
                              std::fabs(s.weight[0] - 0.5 / M_PI * d[2] / s.pdf)});
        }
        const std::vector<std::uint8_t> fam = bs.tables(4);
        GonioDeviceBrdf db;
        const int e = gonio_device_brdf_init(&db, fam.data(), fam.size());
        std::printf("BRDF: %zu channel(s), %zu θ_i; %s sampler, max |error| %.1e; family blob %zu "
                    "bytes (device %d)\n",
                    info.channels, info.theta_i, bs.method().c_str(), worst, fam.size(), e);
        if (!(worst <= 1e-9) || e != GONIO_DEVICE_OK || info.channels != 1) failures++;
        GonioBrdfReadOptions ro = gonio::Brdf::default_read_options();
        (void)ro;
        const gonio::BrdfSampler cosine =
            brdf.sampler(GONIO_BRDF_METHOD_COSINE, gonio::Brdf::default_sampler_options());
        if (cosine.method() != "cosine") failures++;
        try {
            (void)gonio::Brdf::read("/nonexistent/brdf.binary", ro);
            failures++;
        } catch (const gonio::Error &err) {
            if (err.status() != GONIO_ERR_IO) failures++;
        }
    } catch (const gonio::Error &e) {
        std::fprintf(stderr, "BRDF: unexpected error %d: %s\n", (int)e.status(), e.what());
        failures++;
    }
    if (failures) {
        std::fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    std::printf("C++ example: all checks passed\n");
    return 0;
}
