// gonio.hpp: a header-only C++17 RAII wrapper over the C ABI in gonio.h (docs/C_API.md).
// Failures throw gonio::Error carrying the status code and the library's message.
// SPDX-License-Identifier: MIT OR Apache-2.0
#ifndef GONIO_HPP
#define GONIO_HPP

#include "gonio.h"

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace gonio {

// A failed call: what() is gonio_last_error_message() at the time of the failure.
class Error : public std::runtime_error {
  public:
    Error(GonioStatus status, const char *message) : std::runtime_error(message), status_(status) {}
    GonioStatus status() const noexcept { return status_; }

  private:
    GonioStatus status_;
};

inline void check(GonioStatus status) {
    if (status != GONIO_OK) throw Error(status, gonio_last_error_message());
}

using Vec3 = std::array<double, 3>;

// One sample: a unit direction (gonio's frame) and the sampler's exact density there (per sr).
struct Sample {
    Vec3 direction;
    double pdf;
};

// A sampler of any method and domain. Movable, not copyable; shareable between threads by
// reference (every member function is const and thread-safe).
class Sampler {
  public:
    Sample sample(double u, double v) const {
        GonioSample s;
        check(gonio_sample(ptr_.get(), u, v, &s));
        return {{s.direction[0], s.direction[1], s.direction[2]}, s.pdf};
    }
    double pdf(const Vec3 &d) const {
        double p;
        check(gonio_pdf(ptr_.get(), d[0], d[1], d[2], &p));
        return p;
    }
    double target_pdf(const Vec3 &d) const {
        double p;
        check(gonio_target_pdf(ptr_.get(), d[0], d[1], d[2], &p));
        return p;
    }
    std::array<double, 2> invert(const Vec3 &d) const {
        std::array<double, 2> uv;
        check(gonio_invert(ptr_.get(), d[0], d[1], d[2], &uv[0], &uv[1]));
        return uv;
    }
    // Interleaved batch: uv holds n pairs; returns n directions (3n values) and fills pdfs.
    // An odd number of values (a trailing half point) is an error, not silently dropped.
    std::vector<double> sample_batch(const std::vector<double> &uv, std::vector<double> &pdfs) const {
        if (uv.size() % 2 != 0)
            throw Error(GONIO_ERR_INVALID_ARGUMENT,
                        ("sample_batch: uv holds " + std::to_string(uv.size()) +
                         " values, not pairs (an odd trailing value)")
                            .c_str());
        const size_t n = uv.size() / 2;
        std::vector<double> dirs(3 * n);
        pdfs.resize(n);
        check(gonio_sample_batch(ptr_.get(), uv.data(), n, dirs.data(), pdfs.data()));
        return dirs;
    }
    std::string method() const { return gonio_sampler_method(ptr_.get()); }
    const GonioSampler *get() const noexcept { return ptr_.get(); }

  private:
    friend class Diagram;
    explicit Sampler(GonioSampler *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioSampler *p) const noexcept { gonio_sampler_free(p); }
    };
    std::unique_ptr<GonioSampler, Free> ptr_;
};

// A read photometric file or diagram. Movable, not copyable.
class Diagram {
  public:
    static Diagram read(const std::string &path, GonioFormat format = GONIO_FORMAT_AUTO) {
        GonioDiagram *d = nullptr;
        check(gonio_diagram_read_path(path.c_str(), format, &d));
        return Diagram(d);
    }
    static Diagram read_memory(const std::vector<std::uint8_t> &bytes, GonioFormat format,
                               const std::string &name = "<memory>") {
        GonioDiagram *d = nullptr;
        check(gonio_diagram_read_memory(bytes.data(), bytes.size(), format, name.c_str(), &d));
        return Diagram(d);
    }
    double flux() const {
        double f;
        check(gonio_diagram_flux(ptr_.get(), &f));
        return f;
    }
    std::vector<std::string> warnings() const {
        size_t n = 0;
        check(gonio_diagram_warning_count(ptr_.get(), &n));
        std::vector<std::string> out;
        for (size_t i = 0; i < n; i++) {
            const char *w = nullptr;
            check(gonio_diagram_warning(ptr_.get(), i, &w));
            out.emplace_back(w);
        }
        return out;
    }
    Sampler build(GonioMethod method = GONIO_METHOD_HDS,
                  GonioDomain domain = GONIO_DOMAIN_AUTO) const {
        GonioSampler *s = nullptr;
        check(gonio_sampler_build(ptr_.get(), method, domain, &s));
        return Sampler(s);
    }

  private:
    explicit Diagram(GonioDiagram *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioDiagram *p) const noexcept { gonio_diagram_free(p); }
    };
    std::unique_ptr<GonioDiagram, Free> ptr_;
};

// One sample of an environment map: a unit direction, the exact density there (per sr) and the
// image's linear RGB radiance in that direction.
struct EnvSample {
    Vec3 direction;
    double pdf;
    std::array<float, 3> rgb;
};

// An environment light read from an equirectangular .hdr, .exr or .pfm image. Movable, not
// copyable; shareable between threads by reference (every member function is const).
class EnvMap {
  public:
    static EnvMap read(const std::string &path) {
        GonioEnvMap *m = nullptr;
        check(gonio_envmap_read_path(path.c_str(), &m));
        return EnvMap(m);
    }
    static EnvMap read_memory(const std::vector<std::uint8_t> &bytes,
                              const std::string &name = "<memory>") {
        GonioEnvMap *m = nullptr;
        check(gonio_envmap_read_memory(bytes.data(), bytes.size(), name.c_str(), &m));
        return EnvMap(m);
    }
    /// The defaults of gonio_envmap_options_default (luminance, nearest, no MIS compensation).
    static GonioEnvOptions default_options() {
        GonioEnvOptions o;
        check(gonio_envmap_options_default(&o));
        return o;
    }
    static EnvMap read(const std::string &path, const GonioEnvOptions &options) {
        GonioEnvMap *m = nullptr;
        check(gonio_envmap_read_path_with(path.c_str(), &options, &m));
        return EnvMap(m);
    }
    static EnvMap read_memory(const std::vector<std::uint8_t> &bytes,
                              const GonioEnvOptions &options,
                              const std::string &name = "<memory>") {
        GonioEnvMap *m = nullptr;
        check(gonio_envmap_read_memory_with(bytes.data(), bytes.size(), name.c_str(), &options,
                                            &m));
        return EnvMap(m);
    }
    std::vector<std::string> warnings() const {
        size_t n = 0;
        check(gonio_envmap_warning_count(ptr_.get(), &n));
        std::vector<std::string> out;
        for (size_t i = 0; i < n; i++) {
            const char *w = nullptr;
            check(gonio_envmap_warning(ptr_.get(), i, &w));
            out.emplace_back(w);
        }
        return out;
    }
    EnvSample sample(double u, double v) const {
        EnvSample s;
        check(gonio_envmap_sample(ptr_.get(), u, v, s.direction.data(), &s.pdf, s.rgb.data()));
        return s;
    }
    double pdf(const Vec3 &d) const {
        double p;
        check(gonio_envmap_pdf(ptr_.get(), d[0], d[1], d[2], &p));
        return p;
    }
    std::array<double, 2> invert(const Vec3 &d) const {
        std::array<double, 2> uv;
        check(gonio_envmap_invert(ptr_.get(), d[0], d[1], d[2], &uv[0], &uv[1]));
        return uv;
    }
    std::array<float, 3> eval(const Vec3 &d) const {
        std::array<float, 3> c;
        check(gonio_envmap_eval(ptr_.get(), d[0], d[1], d[2], c.data()));
        return c;
    }
    const GonioEnvMap *get() const noexcept { return ptr_.get(); }
    /// Gives up the handle (the caller frees it, or passes it to gonio_envmap_into_float32).
    GonioEnvMap *release() noexcept { return ptr_.release(); }

  private:
    explicit EnvMap(GonioEnvMap *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioEnvMap *p) const noexcept { gonio_envmap_free(p); }
    };
    std::unique_ptr<GonioEnvMap, Free> ptr_;
};

/// An environment light on its float32 map alone (gonio_envmap_into_float32): float32 batches
/// in structure-of-arrays form, about 10 bytes per pixel beyond the image.
class EnvMapF32 {
  public:
    /// Consumes `map` (it is empty afterwards, whatever happens).
    static EnvMapF32 from(EnvMap &&map) {
        GonioEnvMapF32 *f = nullptr;
        check(gonio_envmap_into_float32(map.release(), &f));
        return EnvMapF32(f);
    }
    /// Samples u.size() points: directions into x, y, z, densities into pdf, RGB into rgb
    /// (3 per point); the vectors are resized.
    void sample(const std::vector<float> &u, const std::vector<float> &v, std::vector<float> &x,
                std::vector<float> &y, std::vector<float> &z, std::vector<float> &pdf,
                std::vector<float> &rgb) const {
        if (u.size() != v.size()) throw Error(GONIO_ERR_INVALID_ARGUMENT, "u and v differ in size");
        const size_t n = u.size();
        x.resize(n), y.resize(n), z.resize(n), pdf.resize(n), rgb.resize(3 * n);
        check(gonio_envmap_f32_sample_batch(ptr_.get(), u.data(), v.data(), n, x.data(),
                                            y.data(), z.data(), pdf.data(), rgb.data()));
    }
    std::vector<float> pdf(const std::vector<float> &x, const std::vector<float> &y,
                           const std::vector<float> &z) const {
        if (x.size() != y.size() || x.size() != z.size())
            throw Error(GONIO_ERR_INVALID_ARGUMENT, "x, y and z differ in size");
        std::vector<float> p(x.size());
        check(gonio_envmap_f32_pdf_batch(ptr_.get(), x.data(), y.data(), z.data(), x.size(),
                                         p.data()));
        return p;
    }
    std::size_t memory_bytes() const {
        std::size_t b = 0;
        check(gonio_envmap_f32_memory_bytes(ptr_.get(), &b));
        return b;
    }
    const GonioEnvMapF32 *get() const noexcept { return ptr_.get(); }

  private:
    explicit EnvMapF32(GonioEnvMapF32 *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioEnvMapF32 *p) const noexcept { gonio_envmap_f32_free(p); }
    };
    std::unique_ptr<GonioEnvMapF32, Free> ptr_;
};

}  // namespace gonio

#endif  // GONIO_HPP
