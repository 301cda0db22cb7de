// gonio.hpp: a header-only C++17 RAII wrapper over the whole C ABI in gonio.h (docs/C_API.md).
// Failures throw gonio::Error carrying the status code and the library's message. Handles are
// movable, not copyable; every member function is const and may be called from any number of
// threads at once (the C ABI's handles are immutable). Batches take gonio::span views (a pointer
// and a length, made from a std::vector, a std::array or a pointer and a count) for their inputs
// and outputs, in both layouts (interleaved and structure-of-arrays) and both precisions (double
// and float: the float overloads run the library's float32 batches); their sizes are checked
// before the C call. A test in scripts/test-c.sh checks that every function of gonio.h is called
// here.
// SPDX-License-Identifier: MIT OR Apache-2.0
#ifndef GONIO_HPP
#define GONIO_HPP

#include "gonio.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace gonio {

// A failed call: what() is gonio_last_error_message() at the time of the failure.
class Error : public std::runtime_error {
  public:
    Error(GonioStatus status, const char *message) : std::runtime_error(message), status_(status) {}
    Error(GonioStatus status, const std::string &message) : Error(status, message.c_str()) {}
    GonioStatus status() const noexcept { return status_; }

  private:
    GonioStatus status_;
};

inline void check(GonioStatus status) {
    if (status != GONIO_OK) throw Error(status, gonio_last_error_message());
}

// A view of n contiguous elements (std::span for C++17): from a std::vector, a std::array, or a
// pointer and a count. A view of const elements is made from a view of mutable ones.
template <class T>
class span {
  public:
    constexpr span() noexcept = default;
    constexpr span(T *data, std::size_t size) noexcept : data_(data), size_(size) {}
    template <class A>
    span(std::vector<std::remove_const_t<T>, A> &v) noexcept : data_(v.data()), size_(v.size()) {}
    template <class A, class U = T, class = std::enable_if_t<std::is_const<U>::value>>
    span(const std::vector<std::remove_const_t<T>, A> &v) noexcept
        : data_(v.data()), size_(v.size()) {}
    template <std::size_t N>
    span(std::array<std::remove_const_t<T>, N> &a) noexcept : data_(a.data()), size_(N) {}
    template <std::size_t N, class U = T, class = std::enable_if_t<std::is_const<U>::value>>
    span(const std::array<std::remove_const_t<T>, N> &a) noexcept : data_(a.data()), size_(N) {}
    template <class U, class = std::enable_if_t<std::is_same<const U, T>::value>>
    span(span<U> s) noexcept : data_(s.data()), size_(s.size()) {}
    constexpr T *data() const noexcept { return data_; }
    constexpr std::size_t size() const noexcept { return size_; }

  private:
    T *data_ = nullptr;
    std::size_t size_ = 0;
};

namespace detail {
// Throws GONIO_ERR_INVALID_ARGUMENT unless `got` == `want` elements.
inline void need(const char *what, std::size_t got, std::size_t want) {
    if (got != want)
        throw Error(GONIO_ERR_INVALID_ARGUMENT, std::string(what) + ": " + std::to_string(got) +
                                                    " elements, expected " + std::to_string(want));
}
// The count of items in an interleaved array of `per`-element items (a trailing partial item is
// an error, not silently dropped).
inline std::size_t items(const char *what, std::size_t values, std::size_t per) {
    if (values % per != 0)
        throw Error(GONIO_ERR_INVALID_ARGUMENT,
                    std::string(what) + ": " + std::to_string(values) + " values, not a multiple of " +
                        std::to_string(per));
    return values / per;
}
// A blob through a size query: `call(buffer, capacity, &size)`.
template <class F>
std::vector<std::uint8_t> blob(F call) {
    std::size_t size = 0;
    check(call(nullptr, 0, &size));
    std::vector<std::uint8_t> out(size);
    check(call(out.data(), out.size(), &size));
    out.resize(size);
    return out;
}
}  // namespace detail

using Vec3 = std::array<double, 3>;

// The library's version string.
inline std::string version() { return gonio_version(); }
// The size limit in bytes of files of `kind` (GONIO_FILE_*), the same in the CLI, C and Python.
inline std::uint64_t read_limit(GonioFileKind kind) { return gonio_read_limit(kind); }
// Sets the limit for the whole process (0: the default).
inline void set_read_limit(GonioFileKind kind, std::uint64_t bytes) {
    check(gonio_set_read_limit(kind, bytes));
}

// One sample: a unit direction (gonio's frame) and the sampler's exact density there (per sr).
struct Sample {
    Vec3 direction;
    double pdf;
};

class Diagram;

// A sampler of any method and domain (Diagram::build, Diagram::build_with).
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
    std::string method() const { return gonio_sampler_method(ptr_.get()); }
    GonioDomain domain() const {
        GonioDomain d;
        check(gonio_sampler_domain(ptr_.get(), &d));
        return d;
    }
    // The guaranteed (min, max) of pdf / target_pdf, or none when the method states none.
    std::optional<std::pair<double, double>> ratio_bound() const {
        double lo = 0.0, hi = 0.0;
        const GonioStatus s = gonio_sampler_ratio_bound(ptr_.get(), &lo, &hi);
        if (s == GONIO_ERR_UNSUPPORTED) return std::nullopt;
        check(s);
        return std::make_pair(lo, hi);
    }
    // ∫ of the diagram over the domain (unit × sr).
    double target_power() const {
        double p;
        check(gonio_sampler_target_power(ptr_.get(), &p));
        return p;
    }

    // Interleaved batches: uv holds n pairs; dirs 3n values, pdf n (or uv 2n for invert).
    void sample_batch(span<const double> uv, span<double> dirs, span<double> pdf) const {
        const std::size_t n = detail::items("uv", uv.size(), 2);
        detail::need("dirs", dirs.size(), 3 * n), detail::need("pdf", pdf.size(), n);
        check(gonio_sample_batch(ptr_.get(), uv.data(), n, dirs.data(), pdf.data()));
    }
    void sample_batch(span<const float> uv, span<float> dirs, span<float> pdf) const {
        const std::size_t n = detail::items("uv", uv.size(), 2);
        detail::need("dirs", dirs.size(), 3 * n), detail::need("pdf", pdf.size(), n);
        check(gonio_sample_batch_f32(ptr_.get(), uv.data(), n, dirs.data(), pdf.data()));
    }
    void pdf_batch(span<const double> dirs, span<double> out) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("out", out.size(), n);
        check(gonio_pdf_batch(ptr_.get(), dirs.data(), n, out.data()));
    }
    void pdf_batch(span<const float> dirs, span<float> out) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("out", out.size(), n);
        check(gonio_pdf_batch_f32(ptr_.get(), dirs.data(), n, out.data()));
    }
    void target_pdf_batch(span<const double> dirs, span<double> out) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("out", out.size(), n);
        check(gonio_target_pdf_batch(ptr_.get(), dirs.data(), n, out.data()));
    }
    void target_pdf_batch(span<const float> dirs, span<float> out) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("out", out.size(), n);
        check(gonio_target_pdf_batch_f32(ptr_.get(), dirs.data(), n, out.data()));
    }
    void invert_batch(span<const double> dirs, span<double> uv) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("uv", uv.size(), 2 * n);
        check(gonio_invert_batch(ptr_.get(), dirs.data(), n, uv.data()));
    }
    void invert_batch(span<const float> dirs, span<float> uv) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("uv", uv.size(), 2 * n);
        check(gonio_invert_batch_f32(ptr_.get(), dirs.data(), n, uv.data()));
    }

    // Structure-of-arrays batches: every array of one length n.
    void sample_batch_soa(span<const double> u, span<const double> v, span<double> x,
                          span<double> y, span<double> z, span<double> pdf) const {
        const std::size_t n = u.size();
        detail::need("v", v.size(), n), detail::need("x", x.size(), n);
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("pdf", pdf.size(), n);
        check(gonio_sample_batch_soa(ptr_.get(), u.data(), v.data(), n, x.data(), y.data(),
                                     z.data(), pdf.data()));
    }
    void sample_batch_soa(span<const float> u, span<const float> v, span<float> x, span<float> y,
                          span<float> z, span<float> pdf) const {
        const std::size_t n = u.size();
        detail::need("v", v.size(), n), detail::need("x", x.size(), n);
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("pdf", pdf.size(), n);
        check(gonio_sample_batch_soa_f32(ptr_.get(), u.data(), v.data(), n, x.data(), y.data(),
                                         z.data(), pdf.data()));
    }
    void pdf_batch_soa(span<const double> x, span<const double> y, span<const double> z,
                       span<double> out) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("out", out.size(), n);
        check(gonio_pdf_batch_soa(ptr_.get(), x.data(), y.data(), z.data(), n, out.data()));
    }
    void pdf_batch_soa(span<const float> x, span<const float> y, span<const float> z,
                       span<float> out) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("out", out.size(), n);
        check(gonio_pdf_batch_soa_f32(ptr_.get(), x.data(), y.data(), z.data(), n, out.data()));
    }
    void target_pdf_batch_soa(span<const double> x, span<const double> y, span<const double> z,
                              span<double> out) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("out", out.size(), n);
        check(gonio_target_pdf_batch_soa(ptr_.get(), x.data(), y.data(), z.data(), n, out.data()));
    }
    void target_pdf_batch_soa(span<const float> x, span<const float> y, span<const float> z,
                              span<float> out) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("out", out.size(), n);
        check(gonio_target_pdf_batch_soa_f32(ptr_.get(), x.data(), y.data(), z.data(), n,
                                             out.data()));
    }
    void invert_batch_soa(span<const double> x, span<const double> y, span<const double> z,
                          span<double> u, span<double> v) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("u", u.size(), n), detail::need("v", v.size(), n);
        check(gonio_invert_batch_soa(ptr_.get(), x.data(), y.data(), z.data(), n, u.data(),
                                     v.data()));
    }
    void invert_batch_soa(span<const float> x, span<const float> y, span<const float> z,
                          span<float> u, span<float> v) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("u", u.size(), n), detail::need("v", v.size(), n);
        check(gonio_invert_batch_soa_f32(ptr_.get(), x.data(), y.data(), z.data(), n, u.data(),
                                         v.data()));
    }

    // Interleaved batch returning the directions: uv holds n pairs; fills pdfs (resized).
    std::vector<double> sample_batch(const std::vector<double> &uv,
                                     std::vector<double> &pdfs) const {
        const std::size_t n = detail::items("sample_batch: uv", uv.size(), 2);
        std::vector<double> dirs(3 * n);
        pdfs.resize(n);
        sample_batch(span<const double>(uv), span<double>(dirs), span<double>(pdfs));
        return dirs;
    }

    // The HDS map's tables as one blob (docs/TABLES.md), precision 4 (float32) or 8, with the
    // diagram `target` as its grid target (nullptr: none).
    std::vector<std::uint8_t> tables(std::uint32_t precision = 4,
                                     const Diagram *target = nullptr) const;

    const GonioSampler *get() const noexcept { return ptr_.get(); }

  private:
    friend class Diagram;
    explicit Sampler(GonioSampler *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioSampler *p) const noexcept { gonio_sampler_free(p); }
    };
    std::unique_ptr<GonioSampler, Free> ptr_;
};

// A read photometric file or diagram.
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
    double max_intensity() const {
        double m;
        check(gonio_diagram_max_intensity(ptr_.get(), &m));
        return m;
    }
    // The diagram's value (candela for a photometric file) in direction d.
    double intensity(const Vec3 &d) const {
        double v;
        check(gonio_diagram_intensity(ptr_.get(), d[0], d[1], d[2], &v));
        return v;
    }
    // The domain GONIO_DOMAIN_AUTO chooses for this diagram.
    GonioDomain domain() const {
        GonioDomain d;
        check(gonio_diagram_domain(ptr_.get(), &d));
        return d;
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
    static GonioBuildOptions default_build_options() {
        GonioBuildOptions o;
        check(gonio_build_options_default(&o));
        return o;
    }
    Sampler build_with(GonioMethod method, GonioDomain domain,
                       const GonioBuildOptions &options) const {
        GonioSampler *s = nullptr;
        check(gonio_sampler_build_with(ptr_.get(), method, domain, &options, &s));
        return Sampler(s);
    }
    const GonioDiagram *get() const noexcept { return ptr_.get(); }

  private:
    explicit Diagram(GonioDiagram *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioDiagram *p) const noexcept { gonio_diagram_free(p); }
    };
    std::unique_ptr<GonioDiagram, Free> ptr_;
};

inline std::vector<std::uint8_t> Sampler::tables(std::uint32_t precision,
                                                 const Diagram *target) const {
    const GonioDiagram *t = target ? target->get() : nullptr;
    return detail::blob([&](std::uint8_t *b, std::size_t c, std::size_t *s) {
        return gonio_sampler_tables(ptr_.get(), t, precision, b, c, s);
    });
}

// One sample of an environment map: a unit direction, the exact density there (per sr) and the
// image's linear RGB radiance in that direction.
struct EnvSample {
    Vec3 direction;
    double pdf;
    std::array<float, 3> rgb;
};

// An environment light read from an equirectangular .hdr, .exr or .pfm image.
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
    // The defaults of gonio_envmap_options_default (luminance, nearest, no MIS compensation).
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
    // Interleaved batches: uv n pairs, dirs 3n, pdf n, rgb 3n.
    void sample_batch(span<const double> uv, span<double> dirs, span<double> pdf,
                      span<float> rgb) const {
        const std::size_t n = detail::items("uv", uv.size(), 2);
        detail::need("dirs", dirs.size(), 3 * n), detail::need("pdf", pdf.size(), n);
        detail::need("rgb", rgb.size(), 3 * n);
        check(gonio_envmap_sample_batch(ptr_.get(), uv.data(), n, dirs.data(), pdf.data(),
                                        rgb.data()));
    }
    void pdf_batch(span<const double> dirs, span<double> pdf) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("pdf", pdf.size(), n);
        check(gonio_envmap_pdf_batch(ptr_.get(), dirs.data(), n, pdf.data()));
    }
    // (NaN, NaN) where the density is 0.
    void invert_batch(span<const double> dirs, span<double> uv) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("uv", uv.size(), 2 * n);
        check(gonio_envmap_invert_batch(ptr_.get(), dirs.data(), n, uv.data()));
    }
    void eval_batch(span<const double> dirs, span<float> rgb) const {
        const std::size_t n = detail::items("dirs", dirs.size(), 3);
        detail::need("rgb", rgb.size(), 3 * n);
        check(gonio_envmap_eval_batch(ptr_.get(), dirs.data(), n, rgb.data()));
    }
    // The sphere map's tables with the image as the target (docs/TABLES.md).
    std::vector<std::uint8_t> tables(std::uint32_t precision = 4) const {
        return detail::blob([&](std::uint8_t *b, std::size_t c, std::size_t *s) {
            return gonio_envmap_tables(ptr_.get(), precision, b, c, s);
        });
    }
    const GonioEnvMap *get() const noexcept { return ptr_.get(); }
    // Gives up the handle (the caller frees it, or passes it to gonio_envmap_into_float32).
    GonioEnvMap *release() noexcept { return ptr_.release(); }

  private:
    explicit EnvMap(GonioEnvMap *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioEnvMap *p) const noexcept { gonio_envmap_free(p); }
    };
    std::unique_ptr<GonioEnvMap, Free> ptr_;
};

// An environment light on its float32 map alone (gonio_envmap_into_float32): float32 batches
// in structure-of-arrays form, about 10 bytes per pixel beyond the image.
class EnvMapF32 {
  public:
    // Consumes `map` (it is empty afterwards, whatever happens).
    static EnvMapF32 from(EnvMap &&map) {
        GonioEnvMapF32 *f = nullptr;
        check(gonio_envmap_into_float32(map.release(), &f));
        return EnvMapF32(f);
    }
    void sample(span<const float> u, span<const float> v, span<float> x, span<float> y,
                span<float> z, span<float> pdf, span<float> rgb) const {
        const std::size_t n = u.size();
        detail::need("v", v.size(), n), detail::need("x", x.size(), n);
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("pdf", pdf.size(), n), detail::need("rgb", rgb.size(), 3 * n);
        check(gonio_envmap_f32_sample_batch(ptr_.get(), u.data(), v.data(), n, x.data(), y.data(),
                                            z.data(), pdf.data(), rgb.data()));
    }
    // Samples u.size() points into vectors it resizes.
    void sample(const std::vector<float> &u, const std::vector<float> &v, std::vector<float> &x,
                std::vector<float> &y, std::vector<float> &z, std::vector<float> &pdf,
                std::vector<float> &rgb) const {
        const std::size_t n = u.size();
        x.resize(n), y.resize(n), z.resize(n), pdf.resize(n), rgb.resize(3 * n);
        sample(span<const float>(u), span<const float>(v), span<float>(x), span<float>(y),
               span<float>(z), span<float>(pdf), span<float>(rgb));
    }
    void pdf(span<const float> x, span<const float> y, span<const float> z,
             span<float> out) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("out", out.size(), n);
        check(gonio_envmap_f32_pdf_batch(ptr_.get(), x.data(), y.data(), z.data(), n, out.data()));
    }
    std::vector<float> pdf(const std::vector<float> &x, const std::vector<float> &y,
                           const std::vector<float> &z) const {
        std::vector<float> p(x.size());
        pdf(span<const float>(x), span<const float>(y), span<const float>(z), span<float>(p));
        return p;
    }
    // NaN in both where the density is 0.
    void invert(span<const float> x, span<const float> y, span<const float> z, span<float> u,
                span<float> v) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("u", u.size(), n), detail::need("v", v.size(), n);
        check(gonio_envmap_f32_invert_batch(ptr_.get(), x.data(), y.data(), z.data(), n, u.data(),
                                            v.data()));
    }
    void eval(span<const float> x, span<const float> y, span<const float> z,
              span<float> rgb) const {
        const std::size_t n = x.size();
        detail::need("y", y.size(), n), detail::need("z", z.size(), n);
        detail::need("rgb", rgb.size(), 3 * n);
        check(gonio_envmap_f32_eval_batch(ptr_.get(), x.data(), y.data(), z.data(), n, rgb.data()));
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

class Brdf;

// A BRDF sampler of one method (Brdf::sampler). Directions are the local shading frame (z the
// normal), both pointing away from the surface; `wi` arrays hold one direction for every point
// (3 values) or one per point (3n).
class BrdfSampler {
  public:
    std::string method() const { return gonio_brdf_sampler_method(ptr_.get()); }
    GonioBrdfSample sample(const Vec3 &wi, double u, double v) const {
        GonioBrdfSample s;
        check(gonio_brdf_sample(ptr_.get(), wi.data(), u, v, &s));
        return s;
    }
    double pdf(const Vec3 &wi, const Vec3 &wo) const {
        double p;
        check(gonio_brdf_pdf(ptr_.get(), wi.data(), wo.data(), &p));
        return p;
    }
    std::array<double, 2> invert(const Vec3 &wi, const Vec3 &wo) const {
        std::array<double, 2> uv;
        check(gonio_brdf_invert(ptr_.get(), wi.data(), wo.data(), &uv[0], &uv[1]));
        return uv;
    }
    // f_r (R, G, B) of the sampler's own table.
    std::array<double, 3> eval(const Vec3 &wi, const Vec3 &wo) const {
        std::array<double, 3> f;
        check(gonio_brdf_sampler_eval(ptr_.get(), wi.data(), wo.data(), f.data()));
        return f;
    }
    void sample_batch(span<const double> wi, span<const double> uv,
                      span<GonioBrdfSample> out) const {
        const std::size_t n = detail::items("uv", uv.size(), 2);
        detail::need("out", out.size(), n);
        check(gonio_brdf_sample_batch(ptr_.get(), wi.data(), wi_count(wi, n), uv.data(), n,
                                      out.data()));
    }
    void pdf_batch(span<const double> wi, span<const double> wo, span<double> pdf) const {
        const std::size_t n = detail::items("wo", wo.size(), 3);
        detail::need("pdf", pdf.size(), n);
        check(gonio_brdf_pdf_batch(ptr_.get(), wi.data(), wi_count(wi, n), wo.data(), n,
                                   pdf.data()));
    }
    void invert_batch(span<const double> wi, span<const double> wo, span<double> uv) const {
        const std::size_t n = detail::items("wo", wo.size(), 3);
        detail::need("uv", uv.size(), 2 * n);
        check(gonio_brdf_invert_batch(ptr_.get(), wi.data(), wi_count(wi, n), wo.data(), n,
                                      uv.data()));
    }
    // The family blob of an "hds" sampler (docs/TABLES.md "Families"; gonio_device_brdf_*).
    std::vector<std::uint8_t> tables(std::uint32_t precision = 4) const {
        return detail::blob([&](std::uint8_t *b, std::size_t c, std::size_t *s) {
            return gonio_brdf_sampler_tables(ptr_.get(), precision, b, c, s);
        });
    }
    const GonioBrdfSampler *get() const noexcept { return ptr_.get(); }

    // 1 or n incident directions from 3 or 3n values.
    static std::size_t wi_count(span<const double> wi, std::size_t n) {
        const std::size_t k = detail::items("wi", wi.size(), 3);
        if (k != 1 && k != n)
            throw Error(GONIO_ERR_INVALID_ARGUMENT, "wi: " + std::to_string(k) +
                                                        " directions, expected 1 or " +
                                                        std::to_string(n));
        return k;
    }

  private:
    friend class Brdf;
    explicit BrdfSampler(GonioBrdfSampler *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioBrdfSampler *p) const noexcept { gonio_brdf_sampler_free(p); }
    };
    std::unique_ptr<GonioBrdfSampler, Free> ptr_;
};

// A tabulated BRDF (MERL .binary, UTIA .bin or gonio BRDF JSON, recognised from the content).
class Brdf {
  public:
    static GonioBrdfReadOptions default_read_options() {
        GonioBrdfReadOptions o;
        check(gonio_brdf_read_options_default(&o));
        return o;
    }
    static Brdf read(const std::string &path) { return read(path, default_read_options()); }
    static Brdf read(const std::string &path, const GonioBrdfReadOptions &options) {
        GonioBrdf *b = nullptr;
        check(gonio_brdf_read_path(path.c_str(), &options, &b));
        return Brdf(b);
    }
    static Brdf read_memory(const std::vector<std::uint8_t> &bytes,
                            const std::string &name = "<memory>") {
        const GonioBrdfReadOptions o = default_read_options();
        GonioBrdf *b = nullptr;
        check(gonio_brdf_read_memory(bytes.data(), bytes.size(), name.c_str(), &o, &b));
        return Brdf(b);
    }
    GonioBrdfInfo info() const {
        GonioBrdfInfo i;
        check(gonio_brdf_info(ptr_.get(), &i));
        return i;
    }
    std::array<double, 3> eval(const Vec3 &wi, const Vec3 &wo) const {
        std::array<double, 3> f;
        check(gonio_brdf_eval(ptr_.get(), wi.data(), wo.data(), f.data()));
        return f;
    }
    // f (3n values: R, G, B per point) at wo (3n), wi one direction or one per point.
    void eval_batch(span<const double> wi, span<const double> wo, span<double> f) const {
        const std::size_t n = detail::items("wo", wo.size(), 3);
        detail::need("f", f.size(), 3 * n);
        check(gonio_brdf_eval_batch(ptr_.get(), wi.data(), BrdfSampler::wi_count(wi, n),
                                    wo.data(), n, f.data()));
    }
    static GonioBrdfSamplerOptions default_sampler_options() {
        GonioBrdfSamplerOptions o;
        check(gonio_brdf_sampler_options_default(&o));
        return o;
    }
    BrdfSampler sampler(GonioBrdfMethod method = GONIO_BRDF_METHOD_HDS) const {
        return sampler(method, default_sampler_options());
    }
    BrdfSampler sampler(GonioBrdfMethod method, const GonioBrdfSamplerOptions &options) const {
        GonioBrdfSampler *s = nullptr;
        check(gonio_brdf_sampler_build(ptr_.get(), method, &options, &s));
        return BrdfSampler(s);
    }
    const GonioBrdf *get() const noexcept { return ptr_.get(); }

  private:
    explicit Brdf(GonioBrdf *p) : ptr_(p) {}
    struct Free {
        void operator()(GonioBrdf *p) const noexcept { gonio_brdf_free(p); }
    };
    std::unique_ptr<GonioBrdf, Free> ptr_;
};

}  // namespace gonio

#endif  // GONIO_HPP
