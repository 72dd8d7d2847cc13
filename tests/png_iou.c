/* png_iou: the silhouette agreement of two RGBA pictures of the same size, for
 * tests/engine_test.sh. A pixel is "object" when its alpha is at least 128 (both the engine
 * example and sfb_render, as the example calls it, draw the surface opaque on a transparent
 * background). Prints
 *   size WxH
 *   object A B          object pixels in each picture
 *   iou X               |A and B| / |A or B| (1 when both are empty)
 * and exits 0; 1 when a file cannot be read, is not RGBA-convertible or the sizes differ.
 * With --composite OUT.png it also writes the two side by side over white, and a third panel
 * with the pixels only A covers in red and only B covers in blue (for looking at a failure).
 *   cc -std=c99 tests/png_iou.c -o build/png_iou -lm */
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void over_white(unsigned char *dst, const unsigned char *src) {
    int c;
    for (c = 0; c < 3; ++c) dst[c] = (unsigned char)((src[c] * src[3] + 255 * (255 - src[3])) / 255);
    dst[3] = 255;
}

int main(int argc, char **argv) {
    int wa, ha, wb, hb, n, i;
    unsigned char *a, *b;
    long oa = 0, ob = 0, both = 0, either = 0;
    const char *composite = NULL;
    if (argc == 5 && strcmp(argv[3], "--composite") == 0) composite = argv[4];
    else if (argc != 3) {
        fprintf(stderr, "usage: png_iou A.png B.png [--composite OUT.png]\n");
        return 2;
    }
    a = stbi_load(argv[1], &wa, &ha, &n, 4);
    b = stbi_load(argv[2], &wb, &hb, &n, 4);
    if (!a || !b) {
        fprintf(stderr, "png_iou: cannot read %s\n", !a ? argv[1] : argv[2]);
        return 1;
    }
    printf("size %dx%d\n", wa, ha);
    if (wa != wb || ha != hb) {
        fprintf(stderr, "png_iou: sizes differ: %dx%d and %dx%d\n", wa, ha, wb, hb);
        return 1;
    }
    for (i = 0; i < wa * ha; ++i) {
        int ia = a[4 * i + 3] >= 128, ib = b[4 * i + 3] >= 128;
        oa += ia; ob += ib; both += ia && ib; either += ia || ib;
    }
    printf("object %ld %ld\n", oa, ob);
    printf("iou %.6f\n", either ? (double)both / (double)either : 1.0);
    if (composite) {
        int w3 = 3 * wa, x, y;
        unsigned char *out = (unsigned char *)malloc((size_t)w3 * ha * 4);
        if (!out) return 1;
        for (y = 0; y < ha; ++y)
            for (x = 0; x < wa; ++x) {
                size_t s = 4 * ((size_t)y * wa + x), d = 4 * ((size_t)y * w3 + x);
                int ia = a[s + 3] >= 128, ib = b[s + 3] >= 128;
                unsigned char *p = out + d + 8 * (size_t)wa;
                over_white(out + d, a + s);
                over_white(out + d + 4 * (size_t)wa, b + s);
                p[0] = ia && !ib ? 255 : ia && ib ? 200 : ib ? 0 : 255;
                p[1] = ia && !ib ? 0 : ia && ib ? 200 : ib ? 0 : 255;
                p[2] = ia && !ib ? 0 : ia && ib ? 200 : 255;
                p[3] = 255;
            }
        if (!stbi_write_png(composite, w3, ha, 4, out, w3 * 4)) { fprintf(stderr, "png_iou: cannot write %s\n", composite); return 1; }
        free(out);
    }
    stbi_image_free(a);
    stbi_image_free(b);
    return 0;
}
