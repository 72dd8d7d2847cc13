/* A CPU thread pool that a backend owns and lends (the simd backend's kernels and the
 * `parallel` slot of simd, gl and osmesa; sfb__pool in src/sfb_internal.h).
 *
 * threads - 1 workers are started by sfb__pool_start and joined by sfb__pool_stop. A run cuts
 * [first, last) into 4 chunks per thread, of about equal entry counts (with `offsets`: stencil
 * rows) or of equal items; the caller and the workers claim chunks until none is left, and the
 * caller returns once every claimed chunk is done (it never waits for a worker still asleep).
 * Idle workers, and a caller waiting for the last chunks, spin a while before they sleep
 * (SFB__POOL_SPIN below), so that runs coming back to back do not pay a wake-up each.
 * A run while another thread's run holds the pool (pthread_mutex_trylock) returns 0 having run
 * nothing, and so does every run of a pool of one thread: the caller then runs the work
 * itself. Where no thread support is known (SFB__THREADS undefined: _WIN32 and others), a pool
 * always has one thread. */

int sfb__pool_threads(int requested) {
    long n = requested;
    if (n <= 0) {
#if defined(SFB__THREADS) && defined(_SC_NPROCESSORS_ONLN)
        n = sysconf(_SC_NPROCESSORS_ONLN);
#else
        n = 1;
#endif
    }
    if (n < 1) n = 1;
    if (n > SFB__POOL_MAX_THREADS) n = SFB__POOL_MAX_THREADS;
#ifndef SFB__THREADS
    n = 1; /* no thread support known here: single-threaded */
#endif
    return (int)n;
}

#ifdef SFB__THREADS
/* Spinning before sleeping. A sleeping thread woken through its condition variable runs some
 * 30-60 us later on a virtual machine (measured on the 2-core CI VM: a run of 10000 items of
 * 8 ns lost 27 us to it, and a run of 2000 items was slower than one thread), while the core's
 * and the kernels' runs come back to back (an analysis makes about 30 per picture, an eval call
 * one): so an idle worker first spins a while (SFB__POOL_SPINS pauses, about 20-200 us by CPU)
 * watching the job counter, and so does a caller waiting for the last chunks, before either
 * sleeps. The counters are read without the lock there (GCC/Clang atomics; elsewhere no spinning:
 * the lock and the condition variables alone, as before). */
#if defined(__GNUC__) || defined(__clang__)
#  define SFB__POOL_SPIN 1
#  define SFB__POOL_SPINS 4096
static void sfb__pool_pause(void) {
#  if defined(__x86_64__) || defined(__i386__)
    __asm__ __volatile__("pause");
#  elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#  else
    __asm__ __volatile__("" ::: "memory");
#  endif
}
#endif

/* First row in [first, last) whose entries start at or after `e` (last when none). */
static int sfb__pool_row_at(const int *offsets, int first, int last, size_t e) {
    int lo = first, hi = last;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if ((size_t)offsets[mid] < e) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* First item of chunk c of the current job: chunks hold about equal numbers of entries
 * (stencil rows) or of items. */
static int sfb__pool_chunk_start(const sfb__pool *p, int c) {
    if (c <= 0) return p->first;
    if (c >= p->chunks) return p->last;
    if (!p->offsets) return p->first + (int)((long long)(p->last - p->first) * c / p->chunks);
    return sfb__pool_row_at(p->offsets, p->first, p->last, p->entry0 + p->entries / (size_t)p->chunks * (size_t)c);
}

/* Runs chunks of the current job until none is left to claim. Called and returns with
 * p->lock held. A worker that wakes late finds nothing to claim (or joins the next job):
 * the job is only touched between claiming a chunk and counting it done. */
static void sfb__pool_drain(sfb__pool *p) {
    while (p->next_chunk < p->chunks) {
        const int c = p->next_chunk++;
        const int a = sfb__pool_chunk_start(p, c), b = sfb__pool_chunk_start(p, c + 1);
        void (*task)(const void *, const void *, int, int) = p->task;
        const void *owner = p->owner, *arg = p->arg;
        pthread_mutex_unlock(&p->lock);
        if (a < b) task(owner, arg, a, b);
        pthread_mutex_lock(&p->lock);
#ifdef SFB__POOL_SPIN
        if (__atomic_add_fetch(&p->chunks_done, 1, __ATOMIC_RELEASE) == p->chunks) pthread_cond_signal(&p->done);
#else
        if (++p->chunks_done == p->chunks) pthread_cond_signal(&p->done);
#endif
    }
}

static void *sfb__pool_worker(void *arg) {
    sfb__pool *p = (sfb__pool *)arg;
    unsigned long seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
#ifdef SFB__POOL_SPIN
        if (!p->quit && p->generation == seen) {
            int i;
            pthread_mutex_unlock(&p->lock);
            for (i = 0; i < SFB__POOL_SPINS && __atomic_load_n(&p->generation, __ATOMIC_ACQUIRE) == seen && !__atomic_load_n(&p->quit, __ATOMIC_ACQUIRE); ++i)
                sfb__pool_pause();
            pthread_mutex_lock(&p->lock);
        }
#endif
        while (!p->quit && p->generation == seen) pthread_cond_wait(&p->wake, &p->lock);
        if (p->quit) break;
        seen = p->generation;
        sfb__pool_drain(p);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}
#endif /* SFB__THREADS */

void sfb__pool_stop(sfb__pool *p) {
#ifdef SFB__THREADS
    int i;
    if (p->threads <= 1) return;
    pthread_mutex_lock(&p->lock);
#ifdef SFB__POOL_SPIN
    __atomic_store_n(&p->quit, 1, __ATOMIC_RELEASE);
#else
    p->quit = 1;
#endif
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    for (i = 0; i < p->workers; ++i) pthread_join(p->tid[i], NULL);
    p->workers = 0;
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->wake);
    pthread_mutex_destroy(&p->lock);
    pthread_mutex_destroy(&p->busy);
#endif
    p->threads = 1;
}

int sfb__pool_start(sfb__pool *p, int threads, char *why, size_t why_size) {
#ifdef SFB__THREADS
    int i, e;
#endif
    memset(p, 0, sizeof *p);
    p->threads = threads < 1 ? 1 : threads;
#ifdef SFB__THREADS
    if (p->threads == 1) return 1;
    if (pthread_mutex_init(&p->busy, NULL) != 0) goto fail0;
    if (pthread_mutex_init(&p->lock, NULL) != 0) goto fail1;
    if (pthread_cond_init(&p->wake, NULL) != 0) goto fail2;
    if (pthread_cond_init(&p->done, NULL) != 0) goto fail3;
    for (i = 0; i < p->threads - 1; ++i) {
        e = pthread_create(&p->tid[i], NULL, sfb__pool_worker, p);
        if (e != 0) {
            snprintf(why, why_size, "could not start worker thread %d of %d: %s", i + 1, p->threads - 1, strerror(e));
            sfb__pool_stop(p); /* joins the i already running */
            return 0;
        }
        p->workers = i + 1;
    }
    return 1;
fail3:
    pthread_cond_destroy(&p->wake);
fail2:
    pthread_mutex_destroy(&p->lock);
fail1:
    pthread_mutex_destroy(&p->busy);
fail0:
    snprintf(why, why_size, "could not create the thread pool's locks");
    p->threads = 1;
    return 0;
#else
    (void)why; (void)why_size;
    p->threads = 1;
    return 1;
#endif
}

int sfb__pool_run(sfb__pool *p, void (*task)(const void *owner, const void *arg, int a, int b), const void *owner, const void *arg, int first,
                  int last, const int *offsets, size_t e0, size_t entries) {
#ifdef SFB__THREADS
    if (p->threads <= 1 || pthread_mutex_trylock(&p->busy) != 0) return 0;
    pthread_mutex_lock(&p->lock);
    p->task = task;
    p->owner = owner;
    p->arg = arg;
    p->offsets = offsets;
    p->first = first;
    p->last = last;
    p->entry0 = e0;
    p->entries = entries;
    p->chunks = 4 * p->threads; /* several per thread: a late or slow thread takes fewer */
    p->next_chunk = 0;
    p->chunks_done = 0;
#ifdef SFB__POOL_SPIN
    __atomic_store_n(&p->generation, p->generation + 1, __ATOMIC_RELEASE); /* spinning workers read it unlocked */
#else
    ++p->generation;
#endif
    pthread_cond_broadcast(&p->wake);
    sfb__pool_drain(p);
    /* wait for chunks still running on workers, not for workers still asleep */
#ifdef SFB__POOL_SPIN
    if (p->chunks_done < p->chunks) {
        int i;
        pthread_mutex_unlock(&p->lock);
        for (i = 0; i < SFB__POOL_SPINS && __atomic_load_n(&p->chunks_done, __ATOMIC_ACQUIRE) < p->chunks; ++i) sfb__pool_pause();
        pthread_mutex_lock(&p->lock);
    }
#endif
    while (p->chunks_done < p->chunks) pthread_cond_wait(&p->done, &p->lock);
    p->task = NULL;
    p->owner = NULL;
    p->arg = NULL;
    pthread_mutex_unlock(&p->lock);
    pthread_mutex_unlock(&p->busy);
    return 1;
#else
    (void)p; (void)task; (void)owner; (void)arg; (void)first; (void)last; (void)offsets; (void)e0; (void)entries;
    return 0;
#endif
}

/* The `parallel` slot's body for a backend that owns `p`: task(arg, a, b) over its chunks. */
typedef struct sfb__pool_lent {
    void (*task)(void *arg, int first, int last);
    void *arg;
} sfb__pool_lent;

static void sfb__pool_lent_task(const void *owner, const void *arg, int a, int b) {
    const sfb__pool_lent *l = (const sfb__pool_lent *)arg;
    (void)owner;
    l->task(l->arg, a, b);
}

int sfb__pool_lend(sfb__pool *p, void (*task)(void *arg, int first, int last), void *arg, int first, int last) {
    sfb__pool_lent l;
    if (!p || !task || first >= last) return 0;
    l.task = task;
    l.arg = arg;
    return sfb__pool_run(p, sfb__pool_lent_task, NULL, &l, first, last, NULL, 0, 0);
}
