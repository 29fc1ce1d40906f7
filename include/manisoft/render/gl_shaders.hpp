// The GLSL sources of the OpenGL renderer (gl_renderer.hpp): the main pass (Blinn-Phong shading
// with one main light, directional or spot, and ambient light; procedural solid textures: wood,
// marble, fabric, checker, value noise; a shadow map read with one bilinear percentage-closer
// tap; colour and object id written as two outputs of the same pass, MRT) and the shadow pass
// (depth only). ManiSoft paper, section 3.2: the image V_t the policy sees, and the randomized
// setting's textures and lighting.
//
// Mesa llvmpipe runs every instruction of a fragment shader on every pixel (both sides of a
// branch, under a mask), so the main fragment shader is specialised at compile time by #defines
// (main_fragment_source) and kept short.
#pragma once

#include <cstddef>
#include <string>

namespace manisoft::render::detail_gl {

inline constexpr const char* main_vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_projection;
uniform mat4 u_light_view_projection;
out vec3 v_world;
out vec3 v_normal;
out vec3 v_body;
out vec4 v_light_clip;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_body = a_position;
  v_light_clip = u_light_view_projection * world;
  gl_Position = u_view_projection * world;
}
)";

// Specialised per texture kind and shadow switch (TEXTURE_KIND, SHADOWS are #defined before it):
// llvmpipe runs both sides of a branch under an execution mask, so a run-time switch would cost
// every pixel the noise of every texture.
inline constexpr const char* main_fragment_shader = R"(
in vec3 v_world;
in vec3 v_normal;
in vec3 v_body;
in vec4 v_light_clip;
uniform vec3 u_base_color;
uniform vec3 u_secondary_color;
uniform float u_texture_scale;
uniform float u_texture_strength;
uniform float u_specular;
uniform float u_shininess;
uniform vec3 u_light_direction;
uniform vec3 u_light_position;
uniform float u_spot_cos;
uniform vec3 u_light_color;
uniform vec3 u_ambient;
uniform vec3 u_camera_position;
uniform sampler2DShadow u_shadow_map;
uniform vec2 u_shadow_window;  // texels of the map that the light's projection covers (x, y)
uniform float u_shadow_size;   // texels a side of the whole map
uniform float u_shadow_bias;   // depth bias of one texel (normalised light depth)
uniform uint u_object_id;
layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;

// Value noise: trilinear (smoothstep-weighted) blend of a hash at the 8 corners of the unit cell.
// The hash of corner c is fract(q.x q.y q.z (q.x + q.y + q.z)) with q = 17 fract(c 0.3183099 +
// (0.1, 0.2, 0.3)); q's components depend on one axis each, so they are computed once per axis
// (low corner a, high corner b) and the products shared between corners.
float value_noise(vec3 x) {
  vec3 i = floor(x);
  vec3 f = fract(x);
  f = f * f * (3.0 - 2.0 * f);
  vec3 a = fract(i * 0.3183099 + vec3(0.1, 0.2, 0.3)) * 17.0;
  vec3 b = fract((i + 1.0) * 0.3183099 + vec3(0.1, 0.2, 0.3)) * 17.0;
  vec4 xy = vec4(a.x * a.y, b.x * a.y, a.x * b.y, b.x * b.y);  // corners (0,0) (1,0) (0,1) (1,1) in x, y
  vec4 sxy = vec4(a.x + a.y, b.x + a.y, a.x + b.y, b.x + b.y);
  vec4 h0 = fract(xy * a.z * (sxy + a.z));  // z = 0
  vec4 h1 = fract(xy * b.z * (sxy + b.z));  // z = 1
  vec4 h = mix(h0, h1, f.z);
  vec2 hy = mix(h.xz, h.yw, f.x);
  return mix(hy.x, hy.y, f.y);
}
float fbm(vec3 p) {
  float sum = 0.0, amplitude = 0.5;
  for (int i = 0; i < 4; ++i) { sum += amplitude * value_noise(p); p = p * 2.03 + vec3(1.7, 9.2, 5.1); amplitude *= 0.5; }
  return sum / 0.9375;
}
// Pattern weight in [0, 1]: 0 = base colour, 1 = secondary colour.
float pattern(vec3 p) {
  float s = u_texture_scale;
#if TEXTURE_KIND == 1
  {  // wood: growth rings about the body x axis, grain along x, noisy
    float r = length(p.yz) * s + 1.2 * fbm(p * vec3(0.8, 6.0, 6.0) * s * 0.25);
    float ring = fract(r);
    return smoothstep(0.0, 0.25, ring) * smoothstep(1.0, 0.55, ring) * 0.8 + 0.2 * fbm(p * vec3(2.0, 40.0, 40.0));
  }
#elif TEXTURE_KIND == 2
  {  // marble: turbulent sine veins
    float v = sin((p.x + 0.6 * p.y + 0.3 * p.z) * s + 6.0 * fbm(p * s * 0.5));
    return pow(1.0 - abs(v), 6.0);
  }
#elif TEXTURE_KIND == 3
  {  // fabric: over-under weave of two thread sets
    vec3 q = p * s;
    float warp = 0.5 + 0.5 * sin(q.x * 6.2831853);
    float weft = 0.5 + 0.5 * sin((q.y + q.z) * 6.2831853);
    float cell = mod(floor(q.x) + floor(q.y + q.z), 2.0);
    return mix(warp, weft, cell) * 0.8 + 0.2 * value_noise(q * 8.0);
  }
#elif TEXTURE_KIND == 4
  {  // checker
    vec3 q = floor(p * s + vec3(1e-3));
    return mod(q.x + q.y + q.z, 2.0);
  }
#elif TEXTURE_KIND == 5
  {  // noise
    return fbm(p * s);
  }
#endif
  return 0.0;
}
// Fraction of the light reaching the point: one percentage-closer tap over the 2 x 2 texels
// around it, bilinearly weighted (what a GL_LINEAR comparison sampler returns; textureGather of
// the four comparisons is cheaper on llvmpipe). p.xy in [0, 1] spans u_shadow_window texels.
float shadow_factor(float ndl) {
#if LIGHT_KIND == 0
  vec3 p = v_light_clip.xyz * 0.5 + 0.5;  // orthographic: w = 1
#else
  vec3 p = v_light_clip.xyz / v_light_clip.w * 0.5 + 0.5;
#endif
  if (p.z >= 1.0 || p.x <= 0.0 || p.y <= 0.0 || p.x >= 1.0 || p.y >= 1.0) return 1.0;
  float z = p.z - u_shadow_bias * (0.5 + 1.5 * (1.0 - ndl));
  vec2 t = p.xy * u_shadow_window;
#if GATHER
  t -= 0.5;
  vec2 f = fract(t);
  vec4 g = textureGather(u_shadow_map, (floor(t) + 1.0) / u_shadow_size, z);  // (i,j+1) (i+1,j+1) (i+1,j) (i,j)
  return mix(mix(g.w, g.z, f.x), mix(g.x, g.y, f.x), f.y);
#else
  return texture(u_shadow_map, vec3(t / u_shadow_size, z));
#endif
}
// x^(1/2.2) for x in [0, 1] from square roots (llvmpipe's pow is a long polynomial): a fit in
// x^(1/4), x^(1/2), x^(3/4), x within 0.11 of an 8-bit level.
vec3 gamma_encode(vec3 x) {
  vec3 q = sqrt(sqrt(x));
  return q * (0.033443686 + q * (1.24112311 - 0.415407581 * q)) + 0.141269234 * x;
}
void main() {
  vec3 n = normalize(v_normal);  // back faces are culled: n faces the camera's side
  vec3 albedo = u_base_color;
#if TEXTURE_KIND != 0
  albedo = mix(u_base_color, u_secondary_color, clamp(pattern(v_body) * u_texture_strength, 0.0, 1.0));
#endif
#if LIGHT_KIND == 0
  vec3 l = -u_light_direction;
  float lit = 1.0;
#else
  vec3 d = normalize(v_world - u_light_position);
  vec3 l = -d;
  float lit = smoothstep(u_spot_cos, u_spot_cos + 0.03, dot(d, u_light_direction));
#endif
  float ndl = max(dot(n, l), 0.0);
#if SHADOWS
  if (ndl > 0.0 && lit > 0.0) lit *= shadow_factor(ndl);
#endif
  vec3 v = normalize(u_camera_position - v_world);
  vec3 h = normalize(l + v);
  float specular = ndl > 0.0 ? u_specular * pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
  vec3 ambient = u_ambient * (0.8 + 0.2 * n.z);
  vec3 color = albedo * ambient + (albedo * ndl + vec3(specular)) * u_light_color * lit;
  o_color = vec4(gamma_encode(clamp(color, 0.0, 1.0)), 1.0);
  o_id = u_object_id;
}
)";

inline constexpr const char* shadow_vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_model;
uniform mat4 u_light_view_projection;
void main() { gl_Position = u_light_view_projection * (u_model * vec4(a_position, 1.0)); }
)";

inline constexpr const char* shadow_fragment_shader = R"(#version 330 core
void main() {}
)";

/// The main fragment shader specialised for one texture kind (TextureKind as an integer), with or
/// without the shadow lookup, for one light kind (0 directional, 1 spot), with textureGather
/// (GLSL 4.00) or the plain comparison sampler (GLSL 3.30).
inline std::string main_fragment_source(std::size_t texture_kind, std::size_t shadowed, std::size_t light_kind, bool gather) {
  return std::string(gather ? "#version 400 core\n" : "#version 330 core\n") + "#define TEXTURE_KIND " + std::to_string(texture_kind) +
         "\n#define SHADOWS " + std::to_string(shadowed) + "\n#define LIGHT_KIND " + std::to_string(light_kind) + "\n#define GATHER " +
         (gather ? "1" : "0") + "\n" + main_fragment_shader;
}

}  // namespace manisoft::render::detail_gl
