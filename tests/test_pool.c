/*
 * test_pool.c: server/pool.c's order of jobs, driven directly: a gate job holds the threads while the test
 * queues light jobs and heavy parts, then the order in which they ran is checked against the lanes that
 * pool.h documents.
 */
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "../server/pool.h"
#include "support.h"

typedef struct {
    pthread_mutex_t lock;
    pthread_cond_t open;
    int gate_open, gates_in;
    char order[32];
    int n;
} run_log;

typedef struct {
    run_log *log;
    char name;
} job_arg;

static void gate(void *arg)
{
    run_log *l = ((job_arg *)arg)->log;
    pthread_mutex_lock(&l->lock);
    l->gates_in++;
    pthread_cond_broadcast(&l->open);
    while (!l->gate_open)
        pthread_cond_wait(&l->open, &l->lock);
    pthread_mutex_unlock(&l->lock);
}

static void record(void *arg)
{
    job_arg *a = arg;
    pthread_mutex_lock(&a->log->lock);
    a->log->order[a->log->n++] = a->name;
    pthread_mutex_unlock(&a->log->lock);
}

static void log_init(run_log *l)
{
    *l = (run_log){ .n = 0 };
    pthread_mutex_init(&l->lock, NULL);
    pthread_cond_init(&l->open, NULL);
}

static void log_destroy(run_log *l)
{
    pthread_cond_destroy(&l->open);
    pthread_mutex_destroy(&l->lock);
}

static void open_gates(run_log *l)
{
    pthread_mutex_lock(&l->lock);
    l->gate_open = 1;
    pthread_cond_broadcast(&l->open);
    pthread_mutex_unlock(&l->lock);
}

/* Queues `queued` in that order (L: a light job that records, H: a heavy part that runs heavy), a[i] its
 * argument. */
static void queue_jobs(srv_pool *p, run_log *l, const char *queued, job_arg *a, srv_job_fn heavy)
{
    for (size_t i = 0; queued[i]; i++) {
        a[i] = (job_arg){ l, queued[i] };
        if (queued[i] == 'H')
            assert_int_equal(srv_pool_defer_heavy(p, heavy, &a[i], 8), 0);
        else {
            assert_int_equal(srv_pool_reserve(p), 0);
            srv_pool_submit(p, record, &a[i]);
        }
    }
}

/* threads gates hold every thread; then the test queues `queued` (queue_jobs), opens the gates and returns
 * the order in which the rest ran. */
static void run_behind_gates(int threads, const char *queued, char *order)
{
    run_log l;
    log_init(&l);
    srv_pool *p = srv_pool_create(threads, 16, 0);
    assert_non_null(p);
    job_arg g = { &l, 'g' }, a[16];
    for (int i = 0; i < threads; i++) {
        assert_int_equal(srv_pool_reserve(p), 0);
        srv_pool_submit(p, gate, &g);
    }
    pthread_mutex_lock(&l.lock);
    while (l.gates_in < threads)
        pthread_cond_wait(&l.open, &l.lock);
    pthread_mutex_unlock(&l.lock);
    queue_jobs(p, &l, queued, a, record);
    open_gates(&l);
    srv_pool_destroy(p);
    const size_t n = strlen(queued);
    assert_int_equal(l.n, (int)n);
    memcpy(order, l.order, n);
    order[n] = 0;
    log_destroy(&l);
}

/* With one thread there is no lane to keep apart, but the one thread is the thread kept for the rest: a heavy
 * part runs when no light job waits (it was the reverse: heavy parts deferred before light jobs ran first). */
static void one_thread_should_run_light_jobs_before_heavy_parts(void **state)
{
    (void)state;
    char order[32];
    run_behind_gates(1, "HHLL", order);
    assert_string_equal(order, "LLHH");
    run_behind_gates(1, "LHLH", order);
    assert_string_equal(order, "LLHH");
}

/* A heavy part that holds its thread until the test lets it go. */
static void held(void *arg)
{
    job_arg *a = arg;
    record(arg);
    gate(&(job_arg){ a->log, 'g' });
}

/* Polls until n jobs have recorded (at most 30 s); their order. */
static void await_records(run_log *l, int n, char *order)
{
    double until = mono_now() + 30;
    pthread_mutex_lock(&l->lock);
    while (l->n < n && mono_now() < until) {
        pthread_mutex_unlock(&l->lock);
        usleep(1000);
        pthread_mutex_lock(&l->lock);
    }
    memcpy(order, l->order, (size_t)l->n);
    order[l->n] = 0;
    pthread_mutex_unlock(&l->lock);
}

/* Two threads: a heavy part takes one; the other serves every light job, although the heavy parts were queued
 * first, and stays kept for them while it idles: the second heavy part waits for the first (it took the idle
 * thread before, and a light job that came next waited a whole heavy part). */
static void two_threads_should_keep_a_thread_for_light_jobs(void **state)
{
    (void)state;
    run_log l;
    log_init(&l);
    srv_pool *p = srv_pool_create(2, 16, 0);
    assert_non_null(p);
    job_arg a[5];
    queue_jobs(p, &l, "HHLLL", a, held);
    char order[32];
    await_records(&l, 4, order);
    usleep(100000);   /* time for the idle thread to take the second heavy part, if it would */
    await_records(&l, 4, order);
    open_gates(&l);
    srv_pool_destroy(p);
    /* the first H and the L's in either order (two threads record them), and no second H while H holds */
    assert_int_equal(strlen(order), 4);
    int heavies = 0;
    for (int i = 0; i < 4; i++)
        heavies += order[i] == 'H';
    assert_int_equal(heavies, 1);
    assert_int_equal(l.n, 5);
    log_destroy(&l);
}

/* One thread: light jobs keep coming, yet a heavy part goes once 8 have gone before it. */
static void one_thread_should_not_starve_a_heavy_part(void **state)
{
    (void)state;
    char order[32];
    run_behind_gates(1, "HLLLLLLLLLL", order);
    assert_string_equal(order, "LLLLLLLLHLL");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_thread_should_run_light_jobs_before_heavy_parts),
        cmocka_unit_test(two_threads_should_keep_a_thread_for_light_jobs),
        cmocka_unit_test(one_thread_should_not_starve_a_heavy_part),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("pool", tests, NULL, NULL);
}
