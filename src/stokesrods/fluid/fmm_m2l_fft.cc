#include "stokesrods/fluid/fmm_m2l_fft.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <type_traits>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

constexpr int kOffsets = 343;      // v ∈ {−3 … 3}³, at M2lIndex(v)
constexpr int kComponents = 6;     // xx, xy, xz, yy, yz, zz of the symmetric kernel
constexpr int kBlock = 16;         // SIMD block of the spectra (float lanes of AVX-512)
constexpr int kColumnChunk = 2048; // columns of a transform per OpenMP work item
// A block of frequencies as one vector (GCC/Clang vector extensions: one AVX-512 register of
// floats, two of doubles; split by the compiler where the CPU has narrower ones).
typedef float VecF __attribute__((vector_size(kBlock * sizeof(float))));
typedef double VecD __attribute__((vector_size(kBlock * sizeof(double))));

// The 1-D transforms of the separable 3-D transforms, each along the rows of one slice, a batch
// of `len` independent columns per row (the boxes and components of a level, innermost):
//     out[k][c] = Σ_j tw[k][j] in[j][c],   k < K, j < J, c < len,
// complex (re, im arrays) or real on either side; rows `in_stride` and `out_stride` apart. The
// arrays do not overlap (`omp simd`: the loops vectorize without run-time alias checks).
// Built for AVX-512, AVX2 + FMA and baseline x86-64, chosen at run time (as the kernels of
// stokeslet_sum.cc); the loops over columns vectorize.
template <class T>
[[gnu::always_inline]] inline void RowsImpl(int J, int K, std::ptrdiff_t len,
                                            std::ptrdiff_t in_stride, std::ptrdiff_t out_stride,
                                            const T* twr, const T* twi, const T* in_re,
                                            const T* in_im, T* out_re, T* out_im) {
  for (int k = 0; k < K; ++k) {
    T* __restrict yr = out_re + k * out_stride;
    T* __restrict yi = out_im == nullptr ? nullptr : out_im + k * out_stride;
    std::fill(yr, yr + len, T(0));
    if (yi != nullptr) std::fill(yi, yi + len, T(0));
    for (int j = 0; j < J; ++j) {
      const T cr = twr[k * J + j], ci = twi[k * J + j];
      const T* __restrict xr = in_re + j * in_stride;
      const T* __restrict xi = in_im == nullptr ? nullptr : in_im + j * in_stride;
      if (xi == nullptr) {  // real input, complex output
#pragma omp simd
        for (std::ptrdiff_t c = 0; c < len; ++c) {
          yr[c] += cr * xr[c];
          yi[c] += ci * xr[c];
        }
      } else if (yi == nullptr) {  // the real part of the output only
#pragma omp simd
        for (std::ptrdiff_t c = 0; c < len; ++c) yr[c] += cr * xr[c] - ci * xi[c];
      } else {
#pragma omp simd
        for (std::ptrdiff_t c = 0; c < len; ++c) {
          yr[c] += cr * xr[c] - ci * xi[c];
          yi[c] += cr * xi[c] + ci * xr[c];
        }
      }
    }
  }
}

/// One block of kBlock frequencies of every product of a level: c_t += T̂_v ĝ_s (c_d += Σ_e T̂_de ĝ_e,
/// 9 complex multiply–adds per frequency) for the entries (t, s) of every offset v, bucket by
/// bucket (entries [bucket[v], bucket[v + 1]) of `target`, `source`). kernel: 343 × 12 × kBlock
/// (the 6 components' re, im); g, c: boxes × 6 × kBlock (3 components' re, im). The kernel's
/// block of an offset is loaded once into registers for all its entries; g and c of a block of
/// frequencies stay in the L1 or L2 cache.
template <class T>
[[gnu::always_inline]] inline void BlockProductsImpl(const T* kernel, const int* bucket,
                                                     const int* target, const int* source,
                                                     const T* g, T* c) {
  using V = std::conditional_t<std::is_same_v<T, float>, VecF, VecD>;
  static_assert(sizeof(V) == kBlock * sizeof(T));
  auto load = [](V* v, const T* from) { std::memcpy(v, from, sizeof(V)); };
  for (int o = 0; o < kOffsets; ++o) {
    if (bucket[o] == bucket[o + 1]) continue;
    V k[12];  // (re, im) of xx, xy, xz, yy, yz, zz
    for (int i = 0; i < 12; ++i) load(&k[i], kernel + (o * 12 + i) * kBlock);
    for (int e = bucket[o]; e < bucket[o + 1]; ++e) {
      const T* gs = g + source[e] * 6 * kBlock;
      T* ct = c + target[e] * 6 * kBlock;
      V g0r, g0i, g1r, g1i, g2r, g2i;
      load(&g0r, gs);
      load(&g0i, gs + kBlock);
      load(&g1r, gs + 2 * kBlock);
      load(&g1i, gs + 3 * kBlock);
      load(&g2r, gs + 4 * kBlock);
      load(&g2i, gs + 5 * kBlock);
      // Row d of the kernel: components (xx, xy, xz), (xy, yy, yz), (xz, yz, zz).
      auto row = [&](int a, int b, int d, T* out) {
        V re, im;
        load(&re, out);
        load(&im, out + kBlock);
        re += k[2 * a] * g0r - k[2 * a + 1] * g0i + k[2 * b] * g1r - k[2 * b + 1] * g1i +
              k[2 * d] * g2r - k[2 * d + 1] * g2i;
        im += k[2 * a] * g0i + k[2 * a + 1] * g0r + k[2 * b] * g1i + k[2 * b + 1] * g1r +
              k[2 * d] * g2i + k[2 * d + 1] * g2r;
        std::memcpy(out, &re, sizeof(V));
        std::memcpy(out + kBlock, &im, sizeof(V));
      };
      row(0, 1, 2, ct);
      row(1, 3, 4, ct + 2 * kBlock);
      row(2, 4, 5, ct + 4 * kBlock);
    }
  }
}

#define SR_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define SR_INSTANTIATE(T)                                                                       \
  /* in_im null: real input; out_im null: the real part of the output only */                  \
  SR_CLONES void Rows(int J, int K, std::ptrdiff_t len, std::ptrdiff_t in_stride,               \
                      std::ptrdiff_t out_stride, const T* twr, const T* twi, const T* in_re,    \
                      const T* in_im, T* out_re, T* out_im) {                                   \
    RowsImpl<T>(J, K, len, in_stride, out_stride, twr, twi, in_re, in_im, out_re, out_im);     \
  }                                                                                             \
  SR_CLONES void BlockProducts(const T* kernel, const int* bucket, const int* target,         \
                               const int* source, const T* g, T* c) {                           \
    BlockProductsImpl<T>(kernel, bucket, target, source, g, c);                                 \
  }
SR_INSTANTIATE(float)
SR_INSTANTIATE(double)
#undef SR_INSTANTIATE
#undef SR_CLONES

/// tw[k][j] = weight_j e^{sign 2πi k j / N}, k < K, j < J (weight 1, or those of the half
/// spectrum along z when `half_weights`: 1 at j = 0, 2 above).
template <class T>
void Twiddles(int K, int J, int N, double sign, bool half_weights, std::vector<T>* re,
              std::vector<T>* im) {
  re->resize(static_cast<size_t>(K) * J);
  im->resize(static_cast<size_t>(K) * J);
  for (int k = 0; k < K; ++k)
    for (int j = 0; j < J; ++j) {
      const double angle = sign * 2.0 * kPi * static_cast<double>((k * j) % N) / N;
      const double w = half_weights && j > 0 ? 2.0 : 1.0;
      (*re)[static_cast<size_t>(k * J + j)] = static_cast<T>(w * std::cos(angle));
      (*im)[static_cast<size_t>(k * J + j)] = static_cast<T>(w * std::sin(angle));
    }
}

/// The four tables of Forward and Inverse for the order p and grid N (computed once per sum).
template <class T>
void MakeTwiddles(int p, int N, FftTwiddles<T>* tw) {
  const int H = (N + 1) / 2;
  Twiddles<T>(H, p, N, -1.0, false, &tw->forward_z_re, &tw->forward_z_im);
  Twiddles<T>(N, p, N, -1.0, false, &tw->forward_re, &tw->forward_im);
  Twiddles<T>(p, N, N, 1.0, false, &tw->inverse_re, &tw->inverse_im);
  Twiddles<T>(p, H, N, 1.0, true, &tw->inverse_z_re, &tw->inverse_z_im);
  tw->order = p;
  tw->grid = N;
}

/// The steps of one transform, each a set of slices × column chunks run by OpenMP (every output
/// written by one work item: deterministic), over the threads from two chunks' columns on (a
/// chunk is ≈ 50 000 multiply–adds at p = 4; from 2026-11-29, was eight: on a hundred helices
/// every level's transforms, 3 × 200 boxes' columns and fewer, then ran on one thread, 1.2 % of
/// the samples with the second thread waiting).
template <class F>
void ForSlices(int slices, std::ptrdiff_t len, const F& body) {
  const auto chunks = static_cast<int>((len + kColumnChunk - 1) / kColumnChunk);
#pragma omp parallel for schedule(static) if (static_cast<std::ptrdiff_t>(slices) * len > 2 * kColumnChunk && slices * chunks > 1)
  for (int item = 0; item < slices * chunks; ++item) {
    const int slice = item / chunks;
    const std::ptrdiff_t begin = static_cast<std::ptrdiff_t>(item % chunks) * kColumnChunk;
    body(slice, begin, std::min<std::ptrdiff_t>(kColumnChunk, len - begin));
  }
}

/// Makes v at least n long: it grows when too short and never shrinks, so that the levels of one
/// Apply, of different sizes, do not fill their buffers with zeros every time.
template <class T>
void Grow(std::vector<T>* v, std::size_t n) {
  if (v->size() < n) v->resize(n);
}

/// out (re, im: N × N × (N+1)/2 × L) = the transform of in (P × P × P × L, real), the batch of L
/// columns innermost; `temp_*` grow as needed (Grow).
template <class T>
void Forward(int P, int N, std::ptrdiff_t L, const FftTwiddles<T>& tw, const T* in, T* out_re,
             T* out_im, std::vector<T>* temp_re, std::vector<T>* temp_im,
             std::vector<T>* temp2_re, std::vector<T>* temp2_im) {
  const int H = (N + 1) / 2;
  const std::vector<T>&zr = tw.forward_z_re, &zi = tw.forward_z_im;
  const std::vector<T>&yr = tw.forward_re, &yi = tw.forward_im;
  const auto a_size = static_cast<size_t>(P) * P * H * L, b_size = static_cast<size_t>(P) * N * H * L;
  Grow(temp_re, a_size);
  Grow(temp_im, a_size);
  Grow(temp2_re, b_size);
  Grow(temp2_im, b_size);
  T *ar = temp_re->data(), *ai = temp_im->data(), *br = temp2_re->data(), *bi = temp2_im->data();
  ForSlices(P * P, L, [&](int s, std::ptrdiff_t c, std::ptrdiff_t len) {  // along z
    Rows(P, H, len, L, L, zr.data(), zi.data(), in + s * P * L + c, static_cast<const T*>(nullptr),
         ar + s * H * L + c, ai + s * H * L + c);
  });
  const std::ptrdiff_t row_y = H * L;
  ForSlices(P, row_y, [&](int s, std::ptrdiff_t c, std::ptrdiff_t len) {  // along y
    const std::ptrdiff_t i = s * P * row_y + c, o = s * N * row_y + c;
    Rows(P, N, len, row_y, row_y, yr.data(), yi.data(), ar + i, ai + i, br + o, bi + o);
  });
  const std::ptrdiff_t row_x = N * H * L;
  ForSlices(1, row_x, [&](int, std::ptrdiff_t c, std::ptrdiff_t len) {  // along x
    Rows(P, N, len, row_x, row_x, yr.data(), yi.data(), br + c, bi + c, out_re + c, out_im + c);
  });
}

/// out (p × p × p × L, real) = the inverse transform, without N⁻³, of in (re, im: the half
/// spectrum N × N × (N+1)/2 × L), at the first p points per axis.
template <class T>
void Inverse(int p, int N, std::ptrdiff_t L, const FftTwiddles<T>& tw, const T* in_re,
             const T* in_im, T* out, std::vector<T>* temp_re, std::vector<T>* temp_im,
             std::vector<T>* temp2_re, std::vector<T>* temp2_im) {
  const int H = (N + 1) / 2;
  const std::vector<T>&xr = tw.inverse_re, &xi = tw.inverse_im;
  const std::vector<T>&zr = tw.inverse_z_re, &zi = tw.inverse_z_im;
  const auto b_size = static_cast<size_t>(p) * N * H * L, a_size = static_cast<size_t>(p) * p * H * L;
  Grow(temp_re, b_size);
  Grow(temp_im, b_size);
  Grow(temp2_re, a_size);
  Grow(temp2_im, a_size);
  T *br = temp_re->data(), *bi = temp_im->data(), *ar = temp2_re->data(), *ai = temp2_im->data();
  const std::ptrdiff_t row_x = N * H * L;
  ForSlices(1, row_x, [&](int, std::ptrdiff_t c, std::ptrdiff_t len) {  // along x
    Rows(N, p, len, row_x, row_x, xr.data(), xi.data(), in_re + c, in_im + c, br + c, bi + c);
  });
  const std::ptrdiff_t row_y = H * L;
  ForSlices(p, row_y, [&](int s, std::ptrdiff_t c, std::ptrdiff_t len) {  // along y
    const std::ptrdiff_t i = s * N * row_y + c, o = s * p * row_y + c;
    Rows(N, p, len, row_y, row_y, xr.data(), xi.data(), br + i, bi + i, ar + o, ai + o);
  });
  ForSlices(p * p, L, [&](int s, std::ptrdiff_t c, std::ptrdiff_t len) {  // along z, real
    Rows(H, p, len, L, L, zr.data(), zi.data(), ar + s * H * L + c, ai + s * H * L + c,
         out + s * p * L + c, static_cast<T*>(nullptr));
  });
}

std::unique_ptr<M2lSpectra> MakeSpectra(const FmmOperators& op) {
  auto s = std::make_unique<M2lSpectra>();
  const int p = op.order, N = 2 * p - 1, H = p;
  s->order = p;
  s->grid = N;
  s->frequencies = N * N * H;
  s->stride = (s->frequencies + kBlock - 1) / kBlock * kBlock;
  // The surface's lattice cells.
  s->surface_cell.resize(static_cast<size_t>(op.points));
  for (int j = 0; j < op.points; ++j) {
    int cell = 0;
    for (int d = 0; d < 3; ++d) {
      const auto a = static_cast<int>(std::lround((op.surface(d, j) + 1.0) * (p - 1) / 2.0));
      cell = cell * p + a;
    }
    s->surface_cell[static_cast<size_t>(j)] = cell;
  }
  std::vector<bool> on_surface(static_cast<size_t>(p) * p * p, false);
  for (const int cell : s->surface_cell) on_surface[static_cast<size_t>(cell)] = true;
  for (int cell = 0; cell < p * p * p; ++cell)
    if (!on_surface[static_cast<size_t>(cell)]) s->interior_cell.push_back(cell);
  // T_v at the N³ cells of the periodic grid, every offset and component as a column.
  const double eta = 2.0 * kFmmInnerRadius / (p - 1);
  const std::ptrdiff_t L = kOffsets * kComponents;
  std::vector<double> kernel(static_cast<size_t>(N) * N * N * L, 0.0);
  constexpr int kRow[kComponents] = {0, 0, 0, 1, 1, 2}, kCol[kComponents] = {0, 1, 2, 1, 2, 2};
  for (int o = 0; o < kOffsets; ++o) {
    const Vec3 v(o / 49 - 3, o / 7 % 7 - 3, o % 7 - 3);
    if (v.cwiseAbs().maxCoeff() < 2.0) continue;  // neighbours: no M2L
    for (int m = 0; m < N * N * N; ++m) {
      const int mx = m / (N * N), my = m / N % N, mz = m % N;
      auto lag = [&](int i) { return static_cast<double>(i < p ? i : i - N); };  // d from d mod N
      const Mat3 k = StokesletMatrix(eta * Vec3(lag(mx), lag(my), lag(mz)) - v);
      for (int c = 0; c < kComponents; ++c)
        kernel[static_cast<size_t>(m * L + o * kComponents + c)] = k(kRow[c], kCol[c]);
    }
  }
  const auto f_size = static_cast<size_t>(s->frequencies) * L;
  std::vector<double> re(f_size), im(f_size), t1, t2, t3, t4;
  FftTwiddles<double> twiddles;
  MakeTwiddles(N, N, &twiddles);  // the whole lattice, N points per axis
  Forward<double>(N, N, L, twiddles, kernel.data(), re.data(), im.data(), &t1, &t2, &t3, &t4);
  const double scale = 1.0 / (static_cast<double>(N) * N * N);
  // Block-major: block b of kBlock frequencies, offset o, 12 rows (component c's re, im).
  s->values.assign(static_cast<size_t>(s->stride) * kOffsets * 12, 0.0);
  for (int o = 0; o < kOffsets; ++o)
    for (int c = 0; c < kComponents; ++c)
      for (int f = 0; f < s->frequencies; ++f) {
        const auto from = static_cast<size_t>(f * L + o * kComponents + c);
        double* out = s->values.data() +
                      static_cast<size_t>(((f / kBlock) * kOffsets + o) * 12 + 2 * c) * kBlock + f % kBlock;
        out[0] = scale * re[from];
        out[kBlock] = scale * im[from];
      }
  s->values_single.assign(s->values.begin(), s->values.end());
  return s;
}

template <class T>
const T* spectra_values(const M2lSpectra& s) {
  if constexpr (std::is_same_v<T, float>)
    return s.values_single.data();
  else
    return s.values.data();
}

}  // namespace

const M2lSpectra& GetM2lSpectra(const FmmOperators& op) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<M2lSpectra>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& entry = cache[op.order];
  if (!entry) entry = MakeSpectra(op);
  return *entry;
}

M2lByOffset SortByOffset(const FmmList& v_list) {
  M2lByOffset sorted;
  sorted.bucket.assign(kOffsets + 1, 0);
  for (const int o : v_list.offset) ++sorted.bucket[static_cast<size_t>(o) + 1];
  for (int o = 0; o < kOffsets; ++o)
    sorted.bucket[static_cast<size_t>(o) + 1] += sorted.bucket[static_cast<size_t>(o)];
  sorted.target.resize(v_list.box.size());
  sorted.source.resize(v_list.box.size());
  std::vector<int> next(sorted.bucket.begin(), sorted.bucket.end() - 1);
  for (std::size_t t = 0; t + 1 < v_list.start.size(); ++t)
    for (int e = v_list.start[t]; e < v_list.start[t + 1]; ++e) {
      const auto slot = static_cast<size_t>(next[static_cast<size_t>(v_list.offset[static_cast<size_t>(e)])]++);
      sorted.target[slot] = static_cast<int>(t);
      sorted.source[slot] = v_list.box[static_cast<size_t>(e)];
    }
  return sorted;
}

template <class T>
void AddM2lByFft(const M2lSpectra& spectra, const M2lByOffset& entries, const MatX& up,
                 MatX* check, M2lFftScratch<T>* scratch) {
  const int p = spectra.order, N = spectra.grid, F = spectra.frequencies;
  const auto stride = static_cast<std::ptrdiff_t>(spectra.stride);
  const auto n = static_cast<Eigen::Index>(spectra.surface_cell.size());
  const Eigen::Index B = up.cols();
  SR_ASSERT(up.rows() == 3 * n && check->rows() == 3 * n && check->cols() == B,
            "one column of 3n densities per box");
  if (B == 0 || entries.target.empty()) return;
  const std::ptrdiff_t L = 3 * B;
  // The upward densities on the lattice (the cube's inside zero), column d B + b.
  const auto cells = static_cast<std::ptrdiff_t>(p) * p * p;
  Grow(&scratch->grid, static_cast<size_t>(cells * L));
  for (const int cell : spectra.interior_cell)
    std::fill_n(scratch->grid.data() + cell * L, L, T(0));
#pragma omp parallel for schedule(static)
  for (Eigen::Index j = 0; j < n; ++j)
    for (int d = 0; d < 3; ++d) {
      T* row = scratch->grid.data() + spectra.surface_cell[static_cast<size_t>(j)] * L + d * B;
      for (Eigen::Index b = 0; b < B; ++b) row[b] = static_cast<T>(up(3 * j + d, b));
    }
  const auto f_size = static_cast<size_t>(F) * L;
  Grow(&scratch->spectrum_re, f_size);
  Grow(&scratch->spectrum_im, f_size);
  if (scratch->twiddles.order != p || scratch->twiddles.grid != N)
    MakeTwiddles(p, N, &scratch->twiddles);
  Forward<T>(p, N, L, scratch->twiddles, scratch->grid.data(), scratch->spectrum_re.data(),
             scratch->spectrum_im.data(), &scratch->temp_re, &scratch->temp_im, &scratch->temp2_re,
             &scratch->temp2_im);
  // Block-major spectra (BlockProducts): g[block][box][component's re, im][kBlock].
  const int blocks = static_cast<int>(stride / kBlock);
  const std::ptrdiff_t per_block = B * 6 * kBlock;
  Grow(&scratch->boxes, static_cast<size_t>(blocks * per_block));
  Grow(&scratch->sums, static_cast<size_t>(blocks * per_block));
  // (block, box, component, lane) ↔ spectrum_*[f L + d B + b], f = block kBlock + lane < F; the
  // lanes past F are zero in the blocks.
  auto transpose = [&](bool to_blocks, T* blocked) {
#pragma omp parallel for schedule(static)
    for (int block = 0; block < blocks; ++block)
      for (Eigen::Index b = 0; b < B; ++b)
        for (int d = 0; d < 3; ++d) {
          T* re = blocked + block * per_block + (b * 6 + 2 * d) * kBlock;
          T* im = re + kBlock;
          const int lanes = std::min(kBlock, F - block * kBlock);
          const std::ptrdiff_t first = static_cast<std::ptrdiff_t>(block) * kBlock * L + d * B + b;
          T* spectrum_re = scratch->spectrum_re.data() + first;
          T* spectrum_im = scratch->spectrum_im.data() + first;
          for (int lane = 0; lane < lanes; ++lane) {
            if (to_blocks) {
              re[lane] = spectrum_re[lane * L];
              im[lane] = spectrum_im[lane * L];
            } else {
              spectrum_re[lane * L] = re[lane];
              spectrum_im[lane * L] = im[lane];
            }
          }
          if (to_blocks) {
            std::fill(re + lanes, re + kBlock, T(0));
            std::fill(im + lanes, im + kBlock, T(0));
          }
        }
  };
  transpose(true, scratch->boxes.data());
  // The products, block of frequencies by block (each block's sums written by one thread; each
  // box's sum in the order (offset, list position) on any number of threads).
  const T* kernel = spectra_values<T>(spectra);
#pragma omp parallel for schedule(dynamic, 1)
  for (int block = 0; block < blocks; ++block) {
    T* sums = scratch->sums.data() + block * per_block;
    std::fill_n(sums, per_block, T(0));
    BlockProducts(kernel + static_cast<std::ptrdiff_t>(block) * kOffsets * 12 * kBlock,
                  entries.bucket.data(), entries.target.data(), entries.source.data(),
                  scratch->boxes.data() + block * per_block, sums);
  }
  transpose(false, scratch->sums.data());
  Inverse<T>(p, N, L, scratch->twiddles, scratch->spectrum_re.data(), scratch->spectrum_im.data(),
             scratch->grid.data(), &scratch->temp_re, &scratch->temp_im, &scratch->temp2_re,
             &scratch->temp2_im);
#pragma omp parallel for schedule(static)
  for (Eigen::Index b = 0; b < B; ++b)
    for (Eigen::Index j = 0; j < n; ++j)
      for (int d = 0; d < 3; ++d)
        (*check)(3 * j + d, b) += static_cast<double>(
            scratch->grid[static_cast<size_t>(spectra.surface_cell[static_cast<size_t>(j)] * L + d * B + b)]);
}

template void AddM2lByFft<float>(const M2lSpectra&, const M2lByOffset&, const MatX&, MatX*,
                                 M2lFftScratch<float>*);
template void AddM2lByFft<double>(const M2lSpectra&, const M2lByOffset&, const MatX&, MatX*,
                                  M2lFftScratch<double>*);

}  // namespace stokesrods
