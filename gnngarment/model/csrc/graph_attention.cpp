// Fused graph attention (GAT) on the CSR rows of an attention graph: forward and backward.
//
// The graph is `copies` disjoint copies of one base graph of `nodes` nodes (the frames of a
// batch stacked node-major, copy c owning nodes [c*nodes, (c+1)*nodes)); only the base
// graph's index arrays are read, so they stay in cache however many copies there are.
//
// Forward, per destination row i (its incoming edges, self loop included) and head k:
//   l_e = leaky_relu(a_src[j_e, k] + a_dst[i, k]),  m = max_e l_e,
//   s = 1e-16 + sum_e exp(l_e - m),  alpha_e = exp(l_e - m) / s,
//   out[i, k, :] = sum_e alpha_e h[j_e, k, :]   (heads concatenated, or averaged),
// plus the bias, in one pass over the row. m and s are returned for the backward, which
// recomputes alpha from them instead of storing anything per edge:
//   * a row pass (parallel over destinations) gives D[i, k] = sum_e alpha_e g_e with
//     g_e = <dout[i, k, :], h[j_e, k, :]>, and grad a_dst[i, k] = sum_e dz_e, where
//     dz_e = alpha_e (g_e - D[i, k]) leaky_relu'(z_e);
//   * a column pass (parallel over sources, on the transposed graph) gives grad h[j] =
//     sum over j's outgoing edges of alpha_e dout[i, k, :] and grad a_src[j, k] = sum dz_e.
// The row pass keeps alpha_e and dz_e of every edge (2 values per edge and head, freed
// when the backward returns) for the column pass, which reads them through the transposed
// graph's edge numbers: recomputing them there repeated the row pass's per-edge dot
// product <dout, h> (a third of the backward's multiply-adds).
// Every output element is written by one thread in a fixed order: results do not depend
// on the number of threads, and no atomics are needed.

#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <ATen/core/Tensor.h>
#include <ATen/ops/empty.h>
#include <ATen/ops/empty_like.h>
#include <torch/library.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <tuple>
#include <type_traits>
#include <vector>

namespace {

// PyG's softmax epsilon (gnngarment.model.edge_softmax._SOFTMAX_EPS).
constexpr double kSoftmaxEps = 1e-16;
// Rows per parallel task: a row costs ~degree * heads * channels multiply-adds (~1k),
// so smaller tasks would be dominated by scheduling.
constexpr int64_t kGrain = 256;

// Branch-free (the signs of the logits are random: a branch mispredicted half the
// time, and was the largest cost of the forward): one of the two terms is zero.
template <typename T>
inline T leaky_relu(T z, T slope) {
  return std::max(z, T(0)) + slope * std::min(z, T(0));
}

// d leaky_relu / dz, also without a branch.
template <typename T>
inline T leaky_relu_derivative(T z, T slope) {
  return slope + (T(1) - slope) * static_cast<T>(z > T(0));
}

// exp(x) for x <= 0 (every argument here is a logit minus its row max), vectorisable:
// Cephes' expf (range reduction by ln 2, degree-6 polynomial, ~1 ulp). std::exp is a
// scalar libm call, and exp was the largest cost of the softmax.
inline float exp_nonpositive(float x) {
  x = std::max(x, -87.0f);  // 2^n stays a normal float; exp(-87) ~ 1.6e-38 ~ 0 here
  const float magic = 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
  const float n = (x * 1.44269504088896341f + magic) - magic;
  float r = x - n * 0.693359375f;
  r = r + n * 2.12194440e-4f;
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  const int32_t bits = (static_cast<int32_t>(n) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof(scale));
  return p * scale;
}

inline void exp_in_place(float* __restrict__ values, int64_t count) {
#pragma omp simd
  for (int64_t v = 0; v < count; ++v) values[v] = exp_nonpositive(values[v]);
}

inline void exp_in_place(double* values, int64_t count) {
  // float64 serves gradcheck and references: exact libm exp.
  for (int64_t v = 0; v < count; ++v) values[v] = std::exp(values[v]);
}

template <typename T>
inline T dot(const T* __restrict__ a, const T* __restrict__ b, int64_t count) {
  T sum = T(0);
#pragma omp simd reduction(+ : sum)
  for (int64_t c = 0; c < count; ++c) sum += a[c] * b[c];
  return sum;
}


// The sizes and strides every kernel reads.
struct Shape {
  int64_t nodes;    // nodes of the base graph
  int64_t copies;   // disjoint copies of it
  int64_t heads;
  int64_t channels;
  int64_t src_stride;  // row stride of a_src
  int64_t dst_stride;  // row stride of a_dst
  bool concat;
  int64_t width() const { return concat ? heads * channels : channels; }
  int64_t rows() const { return nodes * copies; }
};

// Walks rows begin, begin + 1, ... as (copy offset, base row) without a division per row.
struct RowCursor {
  int64_t nodes, offset, base;
  RowCursor(int64_t row, int64_t nodes_) : nodes(nodes_) {
    const int64_t copy = nodes > 0 ? row / nodes : 0;
    offset = copy * nodes;
    base = row - offset;
  }
  void next() {
    if (++base == nodes) {
      base = 0;
      offset += nodes;
    }
  }
};

// Rows ahead whose neighbours are prefetched. Garment vertex orders are not local (a
// mesh's neighbours lie ~1,400 rows apart in the benchmark skirt), so every neighbour
// row is a cache miss and the kernels wait on memory, not on arithmetic.
constexpr int64_t kPrefetchRows = 3;

// Prefetch the first `bytes` bytes of rows index[e] + offset (e < count) of `base`.
template <typename T>
inline void prefetch_rows(const T* base, const int64_t* index, int64_t count, int64_t offset,
                          int64_t row_stride, int64_t bytes) {
  for (int64_t e = 0; e < count; ++e) {
    const char* row = reinterpret_cast<const char*>(base + (index[e] + offset) * row_stride);
    for (int64_t b = 0; b < bytes; b += 64) __builtin_prefetch(row + b);
  }
}

// Prefetches, for the row `kPrefetchRows` after the cursor's, its neighbours' rows of two
// matrices (e.g. features and scores).
template <typename T>
inline void prefetch_ahead(const RowCursor& cursor, int64_t last, int64_t row,
                           const int64_t* ptr, const int64_t* index, const T* first_base,
                           int64_t first_stride, int64_t first_bytes, const T* second_base,
                           int64_t second_stride, int64_t second_bytes) {
  if (row + kPrefetchRows >= last) return;
  int64_t base = cursor.base + kPrefetchRows, offset = cursor.offset;
  while (base >= cursor.nodes) {
    base -= cursor.nodes;
    offset += cursor.nodes;
  }
  const int64_t begin = ptr[base], count = ptr[base + 1] - begin;
  prefetch_rows(first_base, index + begin, count, offset, first_stride, first_bytes);
  prefetch_rows(second_base, index + begin, count, offset, second_stride, second_bytes);
}

// One accumulator block: 64 bytes (one AVX-512 register, two AVX2 or four SSE ones: the
// compiler splits GCC vector types to what the CPU has). Explicit vectors, because the
// auto-vectoriser vectorised the loop over edges instead (a gather per multiply-add).
template <typename T>
struct BlockOf;
template <>
struct BlockOf<float> {
  typedef float type __attribute__((vector_size(64)));
};
template <>
struct BlockOf<double> {
  typedef double type __attribute__((vector_size(64)));
};
template <typename T>
using Block = typename BlockOf<T>::type;

template <typename T>
constexpr int64_t kLanes = 64 / sizeof(T);

// out[0:count] = sum_e coef[e * coef_stride] * rows[index[e] + offset][0:count], rows of
// `row_stride` elements: the SpMM row kernel, accumulating in registers block by block
// (accumulating into memory chained every edge's multiply-add through a store).
template <typename T>
inline void weighted_rows(T* __restrict__ out, int64_t count, const int64_t* index,
                          int64_t offset, int64_t edges, const T* coef, int64_t coef_stride,
                          const T* rows, int64_t row_stride) {
  constexpr int64_t lanes = kLanes<T>;
  int64_t c0 = 0;
  for (; c0 + lanes <= count; c0 += lanes) {
    Block<T> acc = {};
    for (int64_t e = 0; e < edges; ++e) {
      Block<T> row;
      std::memcpy(&row, rows + (index[e] + offset) * row_stride + c0, sizeof(row));
      acc += coef[e * coef_stride] * row;
    }
    std::memcpy(out + c0, &acc, sizeof(acc));
  }
  const int64_t rest = count - c0;
  if (rest > 0) {  // a partial block (all of it for narrow layers, e.g. 3 channels)
    T acc[lanes] = {};
    for (int64_t e = 0; e < edges; ++e) {
      const T w = coef[e * coef_stride];
      const T* __restrict__ row = rows + (index[e] + offset) * row_stride + c0;
#pragma GCC unroll 4
      for (int64_t l = 0; l < rest; ++l) acc[l] += w * row[l];
    }
    std::copy(acc, acc + rest, out + c0);
  }
}

// z = a_src[j_e, k] + a_dst[i, k] of a row's edges, in (edge, head) order.
template <typename T>
__attribute__((always_inline)) inline void row_sums(const int64_t* neighbours, int64_t degree, int64_t offset, const T* a_src,
                     int64_t src_stride, const T* __restrict__ a_dst_row, int64_t heads,
                     T* __restrict__ z) {
  for (int64_t e = 0; e < degree; ++e) {
    const T* __restrict__ source = a_src + (neighbours[e] + offset) * src_stride;
    for (int64_t k = 0; k < heads; ++k) z[e * heads + k] = source[k] + a_dst_row[k];
  }
}

// Softmax weights of one row from its z values, in place: alpha = exp(leaky(z) - m) / s
// times `scale`, with m and s the row's maxima and sums (computed and stored when
// `compute` is set, read otherwise); `derivative` (if not null) gets leaky_relu'(z).
template <typename T>
__attribute__((always_inline)) inline void row_softmax(T* __restrict__ alpha, T* __restrict__ derivative, int64_t degree,
                        int64_t heads, T slope, T scale, bool compute, T* __restrict__ maximum,
                        T* __restrict__ total, T* __restrict__ inverse) {
  const int64_t count = degree * heads;
  if (derivative != nullptr)
    for (int64_t v = 0; v < count; ++v) derivative[v] = leaky_relu_derivative(alpha[v], slope);
  for (int64_t v = 0; v < count; ++v) alpha[v] = leaky_relu(alpha[v], slope);
  if (compute) {
    std::fill(maximum, maximum + heads, -std::numeric_limits<T>::infinity());
    for (int64_t e = 0; e < degree; ++e)
      for (int64_t k = 0; k < heads; ++k)
        maximum[k] = std::max(maximum[k], alpha[e * heads + k]);
  }
  for (int64_t e = 0; e < degree; ++e)
    for (int64_t k = 0; k < heads; ++k) alpha[e * heads + k] -= maximum[k];
  exp_in_place(alpha, count);
  if (compute) {
    std::fill(total, total + heads, T(kSoftmaxEps));
    for (int64_t e = 0; e < degree; ++e)
      for (int64_t k = 0; k < heads; ++k) total[k] += alpha[e * heads + k];
  }
  for (int64_t k = 0; k < heads; ++k) inverse[k] = scale / total[k];
  for (int64_t e = 0; e < degree; ++e)
    for (int64_t k = 0; k < heads; ++k) alpha[e * heads + k] *= inverse[k];
}

template <typename T, int64_t kHeads>
void forward_kernel(const int64_t* ptr, const int64_t* source, const Shape s, const T* h,
                    const T* a_src, const T* a_dst, const T* bias, T slope, T* out,
                    T* row_max, T* row_sum) {
  // kHeads > 0: the head count known at compile time (its loops unrolled).
  const int64_t heads = kHeads > 0 ? kHeads : s.heads;
  const int64_t channels = s.channels, width = s.width();
  const int64_t stride = heads * channels;
  const T scale = s.concat ? T(1) : T(1) / T(heads);  // head mean folded into the weights
  at::parallel_for(0, s.rows(), kGrain, [&](int64_t begin, int64_t end) {
    std::vector<T> alpha, inverse(heads), per_head(stride);
    RowCursor cursor(begin, s.nodes);
    for (int64_t i = begin; i < end; ++i, cursor.next()) {
      prefetch_ahead(cursor, end, i, ptr, source, h, stride, stride * sizeof(T), a_src,
                     s.src_stride, heads * sizeof(T));
      const int64_t first = ptr[cursor.base], degree = ptr[cursor.base + 1] - first;
      const int64_t* neighbours = source + first;
      alpha.resize(degree * heads);
      row_sums(neighbours, degree, cursor.offset, a_src, s.src_stride, a_dst + i * s.dst_stride,
               heads, alpha.data());
      row_softmax(alpha.data(), static_cast<T*>(nullptr), degree, heads, slope, scale, true,
                  row_max + i * heads, row_sum + i * heads, inverse.data());
      T* row = out + i * width;
      T* target = s.concat ? row : per_head.data();
      for (int64_t k = 0; k < heads; ++k)
        weighted_rows(target + k * channels, channels, neighbours, cursor.offset, degree,
                      alpha.data() + k, heads, h + k * channels, stride);
      if (s.concat) {
        for (int64_t c = 0; c < width; ++c) row[c] += bias[c];
      } else {
        std::copy(bias, bias + channels, row);
        for (int64_t k = 0; k < heads; ++k)
          for (int64_t c = 0; c < channels; ++c) row[c] += per_head[k * channels + c];
      }
    }
  });
}

// Backward, destination side: grad a_dst, and per edge e (numbered copy * edges + its
// place in the base graph's CSR) and head k the coefficient of dout[i] in grad h[j]
// (alpha_e times the head mean's scale) and dz_e.
template <typename T, int64_t kHeads>
void backward_rows(const int64_t* ptr, const int64_t* source, const Shape s, const T* grad,
                   const T* h, const T* a_src, const T* a_dst, const T* row_max,
                   const T* row_sum, T slope, int64_t edges, T* grad_a_dst,
                   T* edge_coefficient, T* edge_dz) {
  // kHeads > 0: the head count known at compile time (its loops unrolled).
  const int64_t heads = kHeads > 0 ? kHeads : s.heads;
  const int64_t channels = s.channels, width = s.width();
  const int64_t stride = heads * channels;
  const T scale = s.concat ? T(1) : T(1) / T(heads);
  at::parallel_for(0, s.rows(), kGrain, [&](int64_t begin, int64_t end) {
    std::vector<T> alpha, derivative, upstream, inverse(heads), maximum(heads), total(heads),
        d(heads);
    RowCursor cursor(begin, s.nodes);
    for (int64_t i = begin; i < end; ++i, cursor.next()) {
      prefetch_ahead(cursor, end, i, ptr, source, h, stride, stride * sizeof(T), a_src,
                     s.src_stride, heads * sizeof(T));
      const int64_t first = ptr[cursor.base], degree = ptr[cursor.base + 1] - first;
      const int64_t edge_base = (cursor.offset / s.nodes) * edges + first;
      const int64_t* neighbours = source + first;
      alpha.resize(degree * heads);
      derivative.resize(degree * heads);
      upstream.resize(degree * heads);
      row_sums(neighbours, degree, cursor.offset, a_src, s.src_stride, a_dst + i * s.dst_stride,
               heads, alpha.data());
      std::copy(row_max + i * heads, row_max + (i + 1) * heads, maximum.begin());
      std::copy(row_sum + i * heads, row_sum + (i + 1) * heads, total.begin());
      row_softmax(alpha.data(), derivative.data(), degree, heads, slope, T(1), false,
                  maximum.data(), total.data(), inverse.data());
      const T* grad_row = grad + i * width;
      std::fill(d.begin(), d.end(), T(0));
      for (int64_t e = 0; e < degree; ++e) {
        const T* features = h + (neighbours[e] + cursor.offset) * stride;
        for (int64_t k = 0; k < heads; ++k) {
          const T g = scale * dot(s.concat ? grad_row + k * channels : grad_row,
                                  features + k * channels, channels);
          upstream[e * heads + k] = g;
          d[k] += alpha[e * heads + k] * g;
        }
      }
      T* grad_dst = grad_a_dst + i * heads;
      T* coefficient = edge_coefficient + edge_base * heads;
      T* dz = edge_dz + edge_base * heads;
      std::fill(grad_dst, grad_dst + heads, T(0));
      for (int64_t e = 0; e < degree; ++e)
        for (int64_t k = 0; k < heads; ++k) {
          const T value = alpha[e * heads + k] * (upstream[e * heads + k] - d[k]) *
                          derivative[e * heads + k];
          grad_dst[k] += value;
          dz[e * heads + k] = value;
          coefficient[e * heads + k] = alpha[e * heads + k] * scale;
        }
    }
  });
}

// Backward, source side (transposed graph: ptr_t / target list the edges out of each
// node, edge_t their numbers in the base graph's CSR): grad h and grad a_src, from the
// row pass's per-edge coefficients and dz.
template <typename T, int64_t kHeads>
void backward_columns(const int64_t* ptr_t, const int64_t* target, const int64_t* edge_t,
                      const Shape s, const T* grad, const T* edge_coefficient,
                      const T* edge_dz, int64_t edges, T* grad_h, T* grad_a_src) {
  // kHeads > 0: the head count known at compile time (its loops unrolled).
  const int64_t heads = kHeads > 0 ? kHeads : s.heads;
  const int64_t channels = s.channels, width = s.width();
  const int64_t stride = heads * channels;
  at::parallel_for(0, s.rows(), kGrain, [&](int64_t begin, int64_t end) {
    std::vector<T> coefficient;
    RowCursor cursor(begin, s.nodes);
    for (int64_t j = begin; j < end; ++j, cursor.next()) {
      prefetch_ahead(cursor, end, j, ptr_t, target, grad, width, width * sizeof(T), grad,
                     width, 0);
      const int64_t first = ptr_t[cursor.base], degree = ptr_t[cursor.base + 1] - first;
      const int64_t* destinations = target + first;
      const int64_t* numbers = edge_t + first;
      const int64_t copy_edges = (cursor.offset / s.nodes) * edges;
      coefficient.resize(degree * heads);
      T* grad_src = grad_a_src + j * heads;
      std::fill(grad_src, grad_src + heads, T(0));
      for (int64_t e = 0; e < degree; ++e) {
        const int64_t edge = (copy_edges + numbers[e]) * heads;
        for (int64_t k = 0; k < heads; ++k) {
          coefficient[e * heads + k] = edge_coefficient[edge + k];
          grad_src[k] += edge_dz[edge + k];
        }
      }
      T* grad_features = grad_h + j * stride;
      for (int64_t k = 0; k < heads; ++k)
        weighted_rows(grad_features + k * channels, channels, destinations, cursor.offset,
                      degree, coefficient.data() + k, heads,
                      grad + (s.concat ? k * channels : 0), width);
    }
  });
}

// Calls run(std::integral_constant<int64_t, H>) with H = heads for the head counts of
// the shipped networks (1, 4: M^mp; 24: E^gg), H = 0 (known at run time only) otherwise.
template <typename Run>
void with_heads(int64_t heads, const Run& run) {
  switch (heads) {
    case 1: return run(std::integral_constant<int64_t, 1>{});
    case 4: return run(std::integral_constant<int64_t, 4>{});
    case 24: return run(std::integral_constant<int64_t, 24>{});
    default: return run(std::integral_constant<int64_t, 0>{});
  }
}

void check_graph(const at::Tensor& ptr, const at::Tensor& index, const char* what) {
  TORCH_CHECK(ptr.dim() == 1 && ptr.scalar_type() == at::kLong && ptr.is_contiguous() &&
                  ptr.numel() >= 1,
              what, ": row pointers must be a contiguous int64 vector");
  TORCH_CHECK(index.dim() == 1 && index.scalar_type() == at::kLong && index.is_contiguous(),
              what, ": indices must be a contiguous int64 vector");
}

// What one call's checked inputs give every block: the row count of all blocks together,
// the heads, the channels per head and the output width.
struct Call {
  int64_t rows, heads, channels, width;
};

// The blocks of a batch: block b is copies[b] copies of the graph (ptr[b], source[b]),
// its rows following block b - 1's. One call runs them all into one output, so that a
// batch of several garments needs no concatenation of per-garment results. Checks every
// block's graph and the score and feature matrices against all of them, once.
Call check_call(at::TensorList ptr, at::TensorList source, at::IntArrayRef copies,
                const at::Tensor& h, const at::Tensor& a_src, const at::Tensor& a_dst,
                bool concat) {
  TORCH_CHECK(ptr.size() == source.size() && ptr.size() == copies.size(),
              "ptr, source and copies must have one entry per block");
  int64_t rows = 0;
  for (size_t b = 0; b < ptr.size(); ++b) {
    check_graph(ptr[b], source[b], "graph");
    TORCH_CHECK(copies[b] >= 0, "copies must be >= 0");
    rows += (ptr[b].numel() - 1) * copies[b];
  }
  TORCH_CHECK(a_src.dim() == 2 && a_dst.dim() == 2 && a_src.sizes() == a_dst.sizes(),
              "a_src and a_dst must both be (N, heads)");
  TORCH_CHECK(a_src.stride(1) == 1 && a_dst.stride(1) == 1,
              "a_src and a_dst must have contiguous rows");
  TORCH_CHECK(a_src.size(0) == rows, "a_src has ", a_src.size(0), " rows, the graph ", rows,
              " nodes (every copy of every block)");
  const int64_t heads = a_src.size(1);
  TORCH_CHECK(heads > 0 && h.dim() == 2 && h.size(0) == rows && h.size(1) % heads == 0 &&
                  h.is_contiguous(),
              "h must be a contiguous (N, heads * channels) matrix");
  TORCH_CHECK(h.scalar_type() == a_src.scalar_type() && h.scalar_type() == a_dst.scalar_type(),
              "h, a_src and a_dst must have one dtype");
  const int64_t channels = h.size(1) / heads;
  return Call{rows, heads, channels, concat ? heads * channels : channels};
}

// Calls run(b, first, count, shape) for each block: its index, its first row and row
// count in the call's matrices, and its kernels' Shape.
template <typename Run>
void for_each_block(at::TensorList ptr, at::IntArrayRef copies, const Call& call,
                    const at::Tensor& a_src, const at::Tensor& a_dst, bool concat,
                    const Run& run) {
  int64_t first = 0;
  for (size_t b = 0; b < ptr.size(); ++b) {
    const int64_t nodes = ptr[b].numel() - 1, count = nodes * copies[b];
    run(b, first, count, Shape{nodes, copies[b], call.heads, call.channels, a_src.stride(0),
                               a_dst.stride(0), concat});
    first += count;
  }
}

std::tuple<at::Tensor, at::Tensor, at::Tensor> graph_attention_forward(
    at::TensorList ptr, at::TensorList source, at::IntArrayRef copies, const at::Tensor& h,
    const at::Tensor& a_src, const at::Tensor& a_dst, const at::Tensor& bias,
    double negative_slope, bool concat) {
  const Call call = check_call(ptr, source, copies, h, a_src, a_dst, concat);
  const at::Tensor bias_ = bias.to(h.scalar_type()).contiguous();
  TORCH_CHECK(bias_.numel() == call.width, "bias must have ", call.width, " values");
  at::Tensor out = at::empty({call.rows, call.width}, h.options());
  at::Tensor row_max = at::empty({call.rows, call.heads}, h.options());
  at::Tensor row_sum = at::empty({call.rows, call.heads}, h.options());
  for_each_block(ptr, copies, call, a_src, a_dst, concat,
                 [&](size_t b, int64_t first, int64_t count, const Shape& s) {
    const auto part = [&](const at::Tensor& t) { return t.narrow(0, first, count); };
    const at::Tensor h_b = part(h), a_src_b = part(a_src), a_dst_b = part(a_dst);
    at::Tensor out_b = part(out), row_max_b = part(row_max), row_sum_b = part(row_sum);
    AT_DISPATCH_FLOATING_TYPES(h.scalar_type(), "graph_attention_forward", [&] {
      const auto run = [&](auto heads) {
        forward_kernel<scalar_t, decltype(heads)::value>(
            ptr[b].data_ptr<int64_t>(), source[b].data_ptr<int64_t>(), s,
            h_b.data_ptr<scalar_t>(), a_src_b.data_ptr<scalar_t>(),
            a_dst_b.data_ptr<scalar_t>(), bias_.data_ptr<scalar_t>(),
            static_cast<scalar_t>(negative_slope), out_b.data_ptr<scalar_t>(),
            row_max_b.data_ptr<scalar_t>(), row_sum_b.data_ptr<scalar_t>());
      };
      with_heads(s.heads, run);
    });
  });
  return {out, row_max, row_sum};
}

std::tuple<at::Tensor, at::Tensor, at::Tensor> graph_attention_backward(
    at::TensorList ptr, at::TensorList source, at::TensorList ptr_t, at::TensorList target,
    at::TensorList edge_t, at::IntArrayRef copies, const at::Tensor& grad, const at::Tensor& h,
    const at::Tensor& a_src, const at::Tensor& a_dst, const at::Tensor& row_max,
    const at::Tensor& row_sum, double negative_slope, bool concat) {
  const Call call = check_call(ptr, source, copies, h, a_src, a_dst, concat);
  TORCH_CHECK(ptr_t.size() == ptr.size() && target.size() == ptr.size() &&
                  edge_t.size() == ptr.size(),
              "the transposed graphs must have one entry per block");
  TORCH_CHECK(row_max.sizes() == a_src.sizes() && row_sum.sizes() == a_src.sizes() &&
                  row_max.is_contiguous() && row_sum.is_contiguous(),
              "row_max and row_sum must be contiguous (N, heads), as the forward gave them");
  TORCH_CHECK(grad.dim() == 2 && grad.size(0) == call.rows && grad.size(1) == call.width &&
                  grad.scalar_type() == h.scalar_type(),
              "grad must be (N, ", call.width, ") of h's dtype");
  const at::Tensor grad_ = grad.contiguous();
  at::Tensor grad_h = at::empty_like(h);
  at::Tensor grad_a_src = at::empty({call.rows, call.heads}, h.options());
  at::Tensor grad_a_dst = at::empty({call.rows, call.heads}, h.options());
  for_each_block(ptr, copies, call, a_src, a_dst, concat,
                 [&](size_t b, int64_t first, int64_t count, const Shape& s) {
    check_graph(ptr_t[b], target[b], "transposed graph");
    check_graph(ptr_t[b], edge_t[b], "transposed graph's edge numbers");
    TORCH_CHECK(ptr_t[b].numel() == ptr[b].numel() && target[b].numel() == source[b].numel() &&
                    edge_t[b].numel() == source[b].numel(),
                "the transposed graph must have the graph's nodes and edges");
    const auto part = [&](const at::Tensor& t) { return t.narrow(0, first, count); };
    const at::Tensor h_b = part(h), a_src_b = part(a_src), a_dst_b = part(a_dst);
    const int64_t edges = source[b].numel();
    at::Tensor edge_coefficient = at::empty({s.copies * edges, s.heads}, h.options());
    at::Tensor edge_dz = at::empty({s.copies * edges, s.heads}, h.options());
    const at::Tensor grad_b = part(grad_), row_max_b = part(row_max), row_sum_b = part(row_sum);
    at::Tensor grad_h_b = part(grad_h), grad_a_src_b = part(grad_a_src),
               grad_a_dst_b = part(grad_a_dst);
    AT_DISPATCH_FLOATING_TYPES(h.scalar_type(), "graph_attention_backward", [&] {
      const auto slope = static_cast<scalar_t>(negative_slope);
      const auto run = [&](auto heads) {
        backward_rows<scalar_t, decltype(heads)::value>(
            ptr[b].data_ptr<int64_t>(), source[b].data_ptr<int64_t>(), s,
            grad_b.data_ptr<scalar_t>(), h_b.data_ptr<scalar_t>(),
            a_src_b.data_ptr<scalar_t>(), a_dst_b.data_ptr<scalar_t>(),
            row_max_b.data_ptr<scalar_t>(), row_sum_b.data_ptr<scalar_t>(), slope, edges,
            grad_a_dst_b.data_ptr<scalar_t>(), edge_coefficient.data_ptr<scalar_t>(),
            edge_dz.data_ptr<scalar_t>());
        backward_columns<scalar_t, decltype(heads)::value>(
            ptr_t[b].data_ptr<int64_t>(), target[b].data_ptr<int64_t>(),
            edge_t[b].data_ptr<int64_t>(), s, grad_b.data_ptr<scalar_t>(),
            edge_coefficient.data_ptr<scalar_t>(), edge_dz.data_ptr<scalar_t>(), edges,
            grad_h_b.data_ptr<scalar_t>(), grad_a_src_b.data_ptr<scalar_t>());
      };
      with_heads(s.heads, run);
    });
  });
  return {grad_h, grad_a_src, grad_a_dst};
}

}  // namespace

TORCH_LIBRARY(gnngarment, m) {
  m.def(
      "graph_attention_forward(Tensor[] ptr, Tensor[] source, int[] copies, Tensor h, "
      "Tensor a_src, Tensor a_dst, Tensor bias, float negative_slope, bool concat) "
      "-> (Tensor, Tensor, Tensor)");
  m.def(
      "graph_attention_backward(Tensor[] ptr, Tensor[] source, Tensor[] ptr_t, "
      "Tensor[] target, Tensor[] edge_t, int[] copies, Tensor grad, Tensor h, Tensor a_src, "
      "Tensor a_dst, Tensor row_max, Tensor row_sum, float negative_slope, bool concat) "
      "-> (Tensor, Tensor, Tensor)");
}

TORCH_LIBRARY_IMPL(gnngarment, CPU, m) {
  m.impl("graph_attention_forward", &graph_attention_forward);
  m.impl("graph_attention_backward", &graph_attention_backward);
}
