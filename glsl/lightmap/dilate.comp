#version 430
// One dilation step: an empty texel (alpha 0) takes the mean of its filled
// 8-neighbours in the same page. Repeated `padding` times, it fills the
// padding around every chart so bilinear lookups near chart edges stay right.
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 5, rgba32f) uniform readonly image2DArray source;
layout(binding = 6, rgba32f) uniform writeonly image2DArray target;

uniform int pageCount;
uniform ivec2 pageSize;

void main() {
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, gl_GlobalInvocationID.z);
    if (t.x >= pageSize.x || t.y >= pageSize.y || t.z >= pageCount) return;
    vec4 center = imageLoad(source, t);
    if (center.a > 0.0) {
        imageStore(target, t, center);
        return;
    }
    vec3 sum = vec3(0.0);
    float count = 0.0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = t.xy + ivec2(dx, dy);
            if (q.x < 0 || q.y < 0 || q.x >= pageSize.x || q.y >= pageSize.y) continue;
            vec4 s = imageLoad(source, ivec3(q, t.z));
            if (s.a > 0.0) {
                sum += s.rgb;
                count += 1.0;
            }
        }
    imageStore(target, t, count > 0.0 ? vec4(sum / count, 1.0) : vec4(0.0));
}
