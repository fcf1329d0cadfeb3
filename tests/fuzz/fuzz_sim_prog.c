/*
 * fuzz_sim_prog.c - libFuzzer target: galil-sim's program store and
 * program interpreter (ctrl_download(): the DL checks of ctrl_store.c and
 * the program parser; then XQ, the threads, UL, BP and a power cycle).
 *
 * Input: [0] bit 0: burn (BP) and power cycle, bit 1: upload (UL); then
 * the program text. A program that is accepted is started with XQ and
 * run for up to 200 servo samples against a trivial plant (the encoders
 * follow the reference). A fresh controller per input.
 */
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "ctrl.h"
#include "gl_err.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define SAMPLES 200

static void run(struct ctrl *c, int n)
{
	struct ctrl_sense in;
	struct ctrl_drive out;
	int i, a;

	memset(&in, 0, sizeof(in));
	in.amp_power = 1;
	for (i = 0; i < n; i++) {
		ctrl_step(c, &in, &out);
		for (a = 0; a < CTRL_AXES; a++)
			if (out.motor_on[a])
				in.enc[a] = out.ref[a];
	}
}

static void drain(struct ctrl *c)
{
	uint8_t buf[512];
	int h;

	for (h = 0; h < CTRL_HANDLES; h++)
		while (ctrl_output(c, h, buf, sizeof(buf)))
			;
	while (ctrl_serial_output(c, buf, sizeof(buf)))
		;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ctrl_cfg cfg;
	struct ctrl *c;
	char resp[512];
	int bad = 0;

	if (size < 1)
		return 0;
	memset(&cfg, 0, sizeof(cfg));
	cfg.model = "DMC4030 Rev 1.2h-sim";
	cfg.serial = 4242;
	cfg.sample_us = 1000;
	c = ctrl_new(&cfg);
	if (!c)
		return 0;
	if (ctrl_download(c, (const char *)data + 1, size - 1, &bad) == 0) {
		if (data[0] & 2) {
			ctrl_handle_open(c, 0);
			ctrl_input(c, 0, (const uint8_t *)"UL\r", 3);
			drain(c);
		}
		(void)ctrl_command(c, "XQ", resp, sizeof(resp));
		run(c, SAMPLES);
		drain(c);
		if (data[0] & 1) {
			(void)ctrl_command(c, "BP", resp, sizeof(resp));
			ctrl_power_cycle(c);
			run(c, SAMPLES / 4);
			drain(c);
		}
	}
	ctrl_free(c);
	return 0;
}
