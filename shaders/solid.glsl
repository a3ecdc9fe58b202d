// Solid, lit, instanced primitives: every limb, drum, cymbal and the stage.
// One unit mesh per primitive kind (cylinder, sphere, box) is drawn once per
// instance with its own model matrix and colour (see virja/render/meshes.py).

#if defined VERTEX_SHADER

uniform mat4 u_view_proj;

in vec3 in_position;   // unit mesh, object space
in vec3 in_normal;
in mat4 in_model;      // per instance: object -> world (metres)
in vec4 in_color;      // per instance: linear RGB, alpha = shininess 0..1

out vec3 v_world;
out vec3 v_normal;
out vec4 v_color;

void main() {
    vec4 world = in_model * vec4(in_position, 1.0);
    // Normals through the inverse transpose.  Every instance is a rotation times a
    // scale (orthogonal columns), whose inverse transpose is each column divided by
    // its squared length: far cheaper per vertex than inverse() on llvmpipe.
    mat3 m = mat3(in_model);
    mat3 normal_matrix = mat3(m[0] / dot(m[0], m[0]), m[1] / dot(m[1], m[1]), m[2] / dot(m[2], m[2]));
    v_world = world.xyz;
    v_normal = normalize(normal_matrix * in_normal);
    v_color = in_color;
    gl_Position = u_view_proj * world;
}

#elif defined FRAGMENT_SHADER

uniform vec3 u_eye;
uniform vec3 u_key_dir;      // towards the key light (normalised)
uniform vec3 u_fill_dir;     // towards the fill light (normalised)
uniform vec3 u_spot_pos;     // stage spot light position
uniform vec3 u_fog_color;

in vec3 v_world;
in vec3 v_normal;
in vec4 v_color;

out vec4 f_color;

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    vec3 to_eye = u_eye - v_world;
    float eye_d2 = dot(to_eye, to_eye);
    vec3 view = to_eye * inversesqrt(eye_d2);
    vec3 base = v_color.rgb;
    float key = max(dot(n, u_key_dir), 0.0);
    float fill = max(dot(n, u_fill_dir), 0.0);
    vec3 to_spot = u_spot_pos - v_world;
    float spot_d2 = dot(to_spot, to_spot);
    float spot = max(dot(n, to_spot), 0.0) * inversesqrt(spot_d2) * 6.0 / (1.0 + spot_d2);
    float r = 1.0 - max(dot(n, view), 0.0);
    float rim = r * r * r * 0.35;
    vec3 h = normalize(u_key_dir + view);
    float s = max(dot(n, h), 0.0);
    s *= s; s *= s; s *= s;  // s^8
    float s2 = s * s; s2 *= s2; s2 *= s2; // s^64
    float spec = mix(s, s2, v_color.a) * v_color.a;
    vec3 lit = base * (0.22 + 0.75 * key + 0.25 * fill + 0.35 * spot) + vec3(spec + rim * 0.6);
    float haze = clamp((sqrt(eye_d2) - 4.0) / 14.0, 0.0, 0.6);
    vec3 rgb = mix(lit, u_fog_color, haze);
    f_color = vec4(sqrt(max(rgb, 0.0)), 1.0);  // gamma 2.0: close to 2.2, far cheaper than pow
}

#endif
