// Stencil evaluation: one invocation per destination row.
//   dst[dst_offset + (row_base + r) * dst_stride + c] =
//       sum_k weights[o + k] * src[src_offset + indices[o + k] * src_stride + c]
// with o = offsets[r] - entry_base, k < sizes[r], c < SFB_LENGTH.
// Accumulation: float, entries in stored order (as the simd backend; ref uses double).
// The backend prepends "#version 430 core" (desktop) or "#version 310 es" + precision
// (GLES 3.1) and "#define SFB_LENGTH n"; the tests validate both with glslangValidator.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer SfbSizes { int sizes[]; };
layout(std430, binding = 1) readonly buffer SfbOffsets { int offsets[]; };
layout(std430, binding = 2) readonly buffer SfbIndices { int indices[]; };
layout(std430, binding = 3) readonly buffer SfbWeights { float weights[]; };
layout(std430, binding = 4) readonly buffer SfbSrc { float src[]; };
layout(std430, binding = 5) writeonly buffer SfbDst { float dst[]; };

uniform int u_first;       // first row of this dispatch (piece-relative)
uniform int u_last;        // one past the last row (piece-relative)
uniform int u_entry_base;  // offsets[] of this piece start here in the whole table
uniform int u_row_base;    // the piece's first row in the whole table
uniform int u_src_offset;
uniform int u_src_stride;
uniform int u_dst_offset;
uniform int u_dst_stride;

void main() {
    int r = int(gl_GlobalInvocationID.x) + u_first;
    if (r >= u_last) return;
    float acc[SFB_LENGTH];
    for (int c = 0; c < SFB_LENGTH; ++c) acc[c] = 0.0;
    int n = sizes[r];
    int o = offsets[r] - u_entry_base;
    for (int k = 0; k < n; ++k) {
        float w = weights[o + k];
        int b = u_src_offset + indices[o + k] * u_src_stride;
        for (int c = 0; c < SFB_LENGTH; ++c) acc[c] += w * src[b + c];
    }
    int d = u_dst_offset + (u_row_base + r) * u_dst_stride;
    for (int c = 0; c < SFB_LENGTH; ++c) dst[d + c] = acc[c];
}
