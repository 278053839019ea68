// GLSL twins of engine/bake/rounding.cpp: PCG hash random numbers, fp16,
// RGBE and accumulator encodings with stochastic or nearest rounding. ROUNDING_NEAREST (a
// define) selects the biased path kept for tests.

uint pcgHash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float uniform01(uint bits) { return float(bits >> 8u) * (1.0 / 16777216.0); }

// fp16 bits of x with stochastic rounding by u in [0,1) (or nearest).
// Saturates at 65504; NaN -> 0.
uint floatToHalf(float x, float u) {
    if (isnan(x)) return 0u;
    uint sign = x < 0.0 ? 0x8000u : 0u;
    float a = min(abs(x), 65504.0);
    uint h = packHalf2x16(vec2(a, 0.0)) & 0x7FFFu;
#ifndef ROUNDING_NEAREST
    float v = unpackHalf2x16(h).x;
    if (v != a) {
        uint lo = v < a ? h : h - 1u;
        uint hi = lo + 1u;
        float vlo = unpackHalf2x16(lo).x;
        float vhi = unpackHalf2x16(hi).x;
        h = (u * (vhi - vlo) < a - vlo) ? hi : lo;
        h = min(h, 0x7BFFu);
    }
#endif
    return sign | h;
}

float halfToFloat(uint h) { return unpackHalf2x16(h & 0xFFFFu).x; }

// RGBE: mantissas in bits 0..23, exponent byte in 24..31; value = m * 2^(e - 136).
uint encodeRgbe(vec3 c, vec3 u) {
    // the C++ twin's rules (engine/bake/rounding.cpp), step for step:
    // negatives, NaN and denormals -> 0; +Inf -> the largest float, which saturates below
    for (int i = 0; i < 3; ++i) c[i] = c[i] >= 1.17549435e-38 ? min(c[i], 3.40282347e38) : 0.0;
    float m = max(c.r, max(c.g, c.b));
    if (m == 0.0) return 0u;
#ifdef ROUNDING_NEAREST
    u = vec3(0.5);
#endif
    int e;
    frexp(m, e);  // m = f * 2^e, f in [0.5, 1)
    for (int attempt = 0; attempt < 2; ++attempt) {
        int es = min(e, 127);  // the largest exponent byte; beyond it the mantissas saturate
        // ldexp, not c * exp2(8 - e): 2^(8 - e) overflows a float for m < 2^-120
        uvec3 q = uvec3(floor(min(vec3(ldexp(c.r, 8 - es), ldexp(c.g, 8 - es), ldexp(c.b, 8 - es)), vec3(256.0)) + u));
        if (e > 127) q = min(q, uvec3(255u));
        if (max(q.r, max(q.g, q.b)) < 256u) {
            int eb = clamp(es + 128, 0, 255);
            return q.r | (q.g << 8u) | (q.b << 16u) | (uint(eb) << 24u);
        }
        e += 1;  // a mantissa rounded up to 256: carry into the exponent and round again
    }
    return 0u;
}

vec3 decodeRgbe(uint v) {
    uint eb = v >> 24u;
    if (eb == 0u) return vec3(0.0);
    vec3 m = vec3(float(v & 255u), float((v >> 8u) & 255u), float((v >> 16u) & 255u));
    return m * exp2(float(int(eb) - 136));
}

// RGB9E5, the bits of GL_RGB9_E5 (r 0..8, g 9..17, b 18..26, shared exponent
// 27..31; value = m * 2^(e - 24)), encoded as the GL spec does but with
// stochastic rounding by u (or nearest). The outgoing radiance map: 4 bytes a
// texel, sampled (and filtered) as GL_RGB9_E5. NaN -> 0, beyond 65408 saturates.
uint encodeRgb9e5(vec3 c, vec3 u) {
#ifdef ROUNDING_NEAREST
    u = vec3(0.5);
#endif
    bvec3 nan = isnan(c);
    c = clamp(vec3(nan.x ? 0.0 : c.x, nan.y ? 0.0 : c.y, nan.z ? 0.0 : c.z), vec3(0.0), vec3(65408.0));
    float m = max(c.r, max(c.g, c.b));
    if (m <= 0.0) return 0u;
    int e;
    frexp(m, e);  // m = f * 2^e, f in [0.5, 1): floor(log2 m) = e - 1
    int ex = max(-16, e - 1) + 16;
    // rounding up must stay below 2^9 (the spec's nearest-rounding check, widened for u < 1)
    if (ex < 31 && m * exp2(float(24 - ex)) >= 511.0) ex += 1;
    uvec3 q = uvec3(min(floor(c * exp2(float(24 - ex)) + u), vec3(511.0)));
    return q.r | (q.g << 9u) | (q.b << 18u) | (uint(ex) << 27u);
}

vec3 decodeRgb9e5(uint v) {
    vec3 m = vec3(float(v & 511u), float((v >> 9u) & 511u), float((v >> 18u) & 511u));
    return m * exp2(float(int(v >> 27u) - 24));
}

// The light map accumulators (update.frag's running mean and its weight) in
// an rg32ui texel: RGB with a shared exponent e and 16-bit mantissas, value
// = m * 2^(e - 31) (e in 0..31: up to 65535), and the weight W as an fp16
// without its sign and four low mantissa bits (11 bits: 7 significant):
// x = r | g << 16, y = b | e << 16 | w << 21. The mean is kept to 1/32768 of
// its largest channel, 32 times finer than fp16: the rounding of a running
// mean adds noise at every sample that grows like sqrt(N) (fp16: 1 % of the
// mean at 4096 samples where L_in varies as much as the mean); W's coarse
// bits only perturb the samples' weights a little (a few % in W, 0.1 % in
// the mean's noise). Stochastic rounding by u (or nearest); NaN and
// negatives -> 0, beyond the largest values saturates.
// floor(x) + 1 with probability fract(x) (exact: floor(x + u) would round
// x + u to a float first, a bias of up to 2^-9 of a step at 16 bits)
float roundUpWithProbability(float x, float u) {
    float f = floor(x);
    return u < x - f ? f + 1.0 : f;
}

uint encodeAccumulatorWeight(float w, float u) {
#ifdef ROUNDING_NEAREST
    u = 0.5;
#endif
    if (!(w > 0.0)) return 0u;
    w = min(w, 64512.0);  // the largest 7-bit-significand fp16
    int e;
    frexp(w, e);  // w = f * 2^e, f in [0.5, 1)
    int k = max(e - 1, -14) - 6;  // w's ulp: 2^k
    float q = min(ldexp(roundUpWithProbability(ldexp(w, -k), u), k), 64512.0);
    return (packHalf2x16(vec2(q, 0.0)) & 0x7FFFu) >> 4u;
}

float decodeAccumulatorWeight(uint bits) { return unpackHalf2x16((bits & 0x7FFu) << 4u).x; }

uvec3 accumulatorMantissas(vec3 c, int ex, vec3 u) {
    return uvec3(roundUpWithProbability(ldexp(c.r, 31 - ex), u.r), roundUpWithProbability(ldexp(c.g, 31 - ex), u.g),
                 roundUpWithProbability(ldexp(c.b, 31 - ex), u.b));
}

uvec2 encodeAccumulator(vec4 s, vec4 u) {
#ifdef ROUNDING_NEAREST
    u = vec4(0.5);
#endif
    vec3 c = s.rgb;
    bvec3 nan = isnan(c);
    c = clamp(vec3(nan.x ? 0.0 : c.x, nan.y ? 0.0 : c.y, nan.z ? 0.0 : c.z), vec3(0.0), vec3(65535.0));
    float m = max(c.r, max(c.g, c.b));
    uvec3 q = uvec3(0u);
    int ex = 0;
    if (m > 0.0) {
        int e;
        frexp(m, e);  // m < 2^e
        ex = clamp(e + 15, 0, 31);
        q = accumulatorMantissas(c, ex, u.rgb);
        if (max(q.r, max(q.g, q.b)) > 65535u && ex < 31) {
            ex += 1;  // a mantissa rounded up to 2^16: carry into the exponent and round again
            q = accumulatorMantissas(c, ex, u.rgb);
        }
        q = min(q, uvec3(65535u));
    }
    return uvec2(q.r | (q.g << 16u), q.b | (uint(ex) << 16u) | (encodeAccumulatorWeight(s.a, u.a) << 21u));
}

vec4 decodeAccumulator(uvec2 p) {
    vec3 m = vec3(float(p.x & 0xFFFFu), float(p.x >> 16u), float(p.y & 0xFFFFu));
    int k = int((p.y >> 16u) & 31u) - 31;
    return vec4(ldexp(m, ivec3(k)), decodeAccumulatorWeight(p.y >> 21u));
}
