/* png_iou: intersection over union of the object silhouettes of two pictures of one size.
 *
 *   png_iou A.png B.png [--bg-a auto|R,G,B] [--bg-b auto|R,G,B] [--tol N] [--min IOU] [--diff OUT.png]
 *
 * A pixel is object when any of its R, G, B channels differs from its picture's background
 * colour by more than --tol (default 8; alpha is ignored). The background is given, or "auto"
 * (default): the colour most of the four corners share (the top-left one on a tie), which is
 * sfb_render's background (default 44,48,56) or render.mjs's (--background, default magenta)
 * whenever the object leaves two corners free. Prints
 *   iou X (A: N object pixels, B: N, both: N, either: N; backgrounds R,G,B and R,G,B)
 * --diff writes a picture of the two silhouettes: white both, red A only, blue B only, black neither.
 * Exit status: 0; 1 when --min is given and the IoU is below it (or neither picture has an
 * object pixel); 2 usage or unreadable pictures or different sizes. */
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int usage(const char *msg) {
    fprintf(stderr, "png_iou: %s\nusage: png_iou A.png B.png [--bg-a auto|R,G,B] [--bg-b auto|R,G,B] [--tol N] [--min IOU] [--diff OUT.png]\n", msg);
    return 2;
}

/* "auto" (bg[3] = 0: pick from the corners) or R,G,B (bg[3] = 1); 0 on a bad value */
static int parse_bg(const char *s, int *bg) {
    char tail;
    if (strcmp(s, "auto") == 0) { bg[3] = 0; return 1; }
    if (sscanf(s, "%d,%d,%d%c", &bg[0], &bg[1], &bg[2], &tail) != 3) return 0;
    if (bg[0] < 0 || bg[0] > 255 || bg[1] < 0 || bg[1] > 255 || bg[2] < 0 || bg[2] > 255) return 0;
    bg[3] = 1;
    return 1;
}

static void corner_bg(const unsigned char *p, int w, int h, int *bg) {
    const unsigned char *c[4];
    int i, j, best = 0, bestn = 0;
    c[0] = p; c[1] = p + 4 * (size_t)(w - 1); c[2] = p + 4 * (size_t)(h - 1) * w; c[3] = p + 4 * ((size_t)(h - 1) * w + (w - 1));
    for (i = 0; i < 4; ++i) {
        int n = 0;
        for (j = 0; j < 4; ++j) n += memcmp(c[i], c[j], 3) == 0;
        if (n > bestn) { bestn = n; best = i; }
    }
    for (i = 0; i < 3; ++i) bg[i] = c[best][i];
}

static int is_object(const unsigned char *px, const int *bg, int tol) {
    int i;
    for (i = 0; i < 3; ++i) if (abs((int)px[i] - bg[i]) > tol) return 1;
    return 0;
}

int main(int argc, char **argv) {
    const char *fa = NULL, *fb = NULL, *diff = NULL;
    int bga[4] = {0, 0, 0, 0}, bgb[4] = {0, 0, 0, 0}, tol = 8, wa, ha, wb, hb, n, i;
    double min = -1.0, iou;
    long na = 0, nb = 0, both = 0, either = 0;
    unsigned char *a, *b, *d = NULL;
    for (i = 1; i < argc; ++i) {
        const char *s = argv[i];
        if (strcmp(s, "--bg-a") == 0 || strcmp(s, "--bg-b") == 0 || strcmp(s, "--tol") == 0 || strcmp(s, "--min") == 0 ||
            strcmp(s, "--diff") == 0) {
            char *end;
            if (i + 1 >= argc) return usage("an option lacks its value");
            ++i;
            if (strcmp(s, "--bg-a") == 0) { if (!parse_bg(argv[i], bga)) return usage("bad --bg-a"); }
            else if (strcmp(s, "--bg-b") == 0) { if (!parse_bg(argv[i], bgb)) return usage("bad --bg-b"); }
            else if (strcmp(s, "--tol") == 0) { tol = (int)strtol(argv[i], &end, 10); if (*end || tol < 0 || tol > 255) return usage("bad --tol"); }
            else if (strcmp(s, "--min") == 0) { min = strtod(argv[i], &end); if (*end || !(min >= 0.0 && min <= 1.0)) return usage("bad --min"); }
            else diff = argv[i];
        } else if (s[0] == '-' && s[1]) return usage("unknown option");
        else if (!fa) fa = s;
        else if (!fb) fb = s;
        else return usage("more than two pictures");
    }
    if (!fa || !fb) return usage("two pictures are needed");
    a = stbi_load(fa, &wa, &ha, &n, 4);
    if (!a) { fprintf(stderr, "png_iou: %s: %s\n", fa, stbi_failure_reason()); return 2; }
    b = stbi_load(fb, &wb, &hb, &n, 4);
    if (!b) { fprintf(stderr, "png_iou: %s: %s\n", fb, stbi_failure_reason()); return 2; }
    if (wa != wb || ha != hb) { fprintf(stderr, "png_iou: sizes differ: %dx%d and %dx%d\n", wa, ha, wb, hb); return 2; }
    if (!bga[3]) corner_bg(a, wa, ha, bga);
    if (!bgb[3]) corner_bg(b, wb, hb, bgb);
    if (diff && !(d = (unsigned char *)calloc((size_t)wa * ha, 3))) { fprintf(stderr, "png_iou: out of memory\n"); return 2; }
    for (i = 0; i < wa * ha; ++i) {
        int oa = is_object(a + 4 * (size_t)i, bga, tol), ob = is_object(b + 4 * (size_t)i, bgb, tol);
        na += oa; nb += ob; both += oa && ob; either += oa || ob;
        if (d) { d[3 * i] = oa ? 255 : 0; d[3 * i + 1] = oa && ob ? 255 : 0; d[3 * i + 2] = ob ? 255 : 0; }
    }
    iou = either ? (double)both / (double)either : 0.0;
    printf("iou %.5f (A: %ld object pixels, B: %ld, both: %ld, either: %ld; backgrounds %d,%d,%d and %d,%d,%d)\n", iou, na, nb, both,
           either, bga[0], bga[1], bga[2], bgb[0], bgb[1], bgb[2]);
    if (d && !stbi_write_png(diff, wa, ha, 3, d, wa * 3)) { fprintf(stderr, "png_iou: cannot write %s\n", diff); return 2; }
    free(d); stbi_image_free(a); stbi_image_free(b);
    if (min >= 0.0 && !(either > 0 && iou >= min)) {
        printf("png_iou: IoU %.5f is below %.5f\n", iou, min);
        return 1;
    }
    return 0;
}
