/* A 5x7 pixel font for the examples' picture labels (digits, . = - : and the lower-case letters
 * the labels use), drawn white at twice its size. Header-only, shared by the panel examples. */
#ifndef SFB_PANEL_FONT_H
#define SFB_PANEL_FONT_H
#include <stddef.h>
#include <string.h>

static const char panel_glyph_chars[] = "0123456789.=-:abcdeghilmnoprstuvxy";
/* rows top to bottom; bit 16 is the leftmost column */
static const unsigned char panel_glyphs[][7] = {
    {14, 17, 19, 21, 25, 17, 14}, {4, 12, 4, 4, 4, 4, 14},    {14, 17, 1, 2, 4, 8, 31},   {30, 1, 1, 14, 1, 1, 30},
    {2, 6, 10, 18, 31, 2, 2},     {31, 16, 30, 1, 1, 17, 14}, {6, 8, 16, 30, 17, 17, 14}, {31, 1, 2, 4, 8, 8, 8},
    {14, 17, 17, 14, 17, 17, 14}, {14, 17, 17, 15, 1, 2, 12}, {0, 0, 0, 0, 0, 12, 12},    {0, 0, 31, 0, 31, 0, 0},
    {0, 0, 0, 31, 0, 0, 0},       {0, 12, 12, 0, 12, 12, 0},  {0, 0, 14, 1, 15, 17, 15},  {16, 16, 22, 25, 17, 17, 30},
    {0, 0, 14, 16, 16, 17, 14},   {1, 1, 13, 19, 17, 17, 15}, {0, 0, 14, 17, 31, 16, 14}, {0, 0, 15, 17, 15, 1, 14},
    {16, 16, 22, 25, 17, 17, 17}, {4, 0, 12, 4, 4, 4, 14},    {12, 4, 4, 4, 4, 4, 14},    {0, 0, 26, 21, 21, 17, 17},
    {0, 0, 22, 25, 17, 17, 17},   {0, 0, 14, 17, 17, 17, 14}, {0, 0, 30, 17, 30, 16, 16}, {0, 0, 22, 25, 16, 16, 16},
    {0, 0, 15, 16, 14, 1, 30},    {8, 8, 28, 8, 8, 9, 6},     {0, 0, 17, 17, 17, 19, 13}, {0, 0, 17, 17, 17, 10, 4},
    {0, 0, 17, 10, 4, 10, 17},    {0, 0, 17, 17, 15, 1, 14}};

/* Draws `text` (on a darkened box) with its top-left corner at (x0, y0) into an RGBA picture `width` pixels wide and
 * `height` high (characters it lacks, and spaces, are blanks; what falls outside is clipped). */
static void panel_draw_text(unsigned char *rgba, int width, int height, int x0, int y0, const char *text) {
    const int scale = 2;
    int c, row, col, dx, dy, n = (int)strlen(text);
    /* a darkened box behind the text, so that it reads on any picture */
    for (dy = -3; dy < 7 * scale + 3; ++dy)
        for (dx = -4; dx < n * 6 * scale + 2; ++dx) {
            int x = x0 + dx, y = y0 + dy;
            unsigned char *p;
            if (x < 0 || y < 0 || x >= width || y >= height) continue;
            p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
            p[0] = (unsigned char)(p[0] / 4); p[1] = (unsigned char)(p[1] / 4); p[2] = (unsigned char)(p[2] / 4); p[3] = 255;
        }
    for (c = 0; c < n; ++c) {
        const char *g = strchr(panel_glyph_chars, text[c]);
        if (text[c] == ' ' || !g) continue;
        for (row = 0; row < 7; ++row)
            for (col = 0; col < 5; ++col)
                if (panel_glyphs[g - panel_glyph_chars][row] & (16 >> col))
                    for (dy = 0; dy < scale; ++dy)
                        for (dx = 0; dx < scale; ++dx) {
                            int x = x0 + (c * 6 + col) * scale + dx, y = y0 + row * scale + dy;
                            unsigned char *p;
                            if (x < 0 || y < 0 || x >= width || y >= height) continue;
                            p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
                            p[0] = p[1] = p[2] = 255; p[3] = 255;
                        }
    }
}
#endif
