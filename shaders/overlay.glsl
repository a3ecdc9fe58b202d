// A screen-space image over the frame: the heads-up display (virja/render/hud.py).
// One quad, placed in pixels, textured with premultiplied-alpha RGBA.

#if defined VERTEX_SHADER

uniform vec4 u_rect;       // x, y, width, height in pixels, origin top-left
uniform vec2 u_viewport;   // frame size in pixels

in vec2 in_corner;         // (0,0) .. (1,1)
out vec2 v_uv;

void main() {
    vec2 px = u_rect.xy + in_corner * u_rect.zw;
    vec2 ndc = vec2(px.x / u_viewport.x * 2.0 - 1.0, 1.0 - px.y / u_viewport.y * 2.0);
    v_uv = in_corner;
    gl_Position = vec4(ndc, 0.0, 1.0);
}

#elif defined FRAGMENT_SHADER

uniform sampler2D u_image;
in vec2 v_uv;
out vec4 f_color;

void main() {
    f_color = texture(u_image, v_uv);
}

#endif
