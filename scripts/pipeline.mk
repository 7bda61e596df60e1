# Reproduction pipeline of the paper (issue #8): material database -> every case of the paper
# (cases/paper/*.json) -> figures -> validation report ($(OUT)/report.md).
#
#   make -f scripts/pipeline.mk ROOT=$PWD BUILD=$PWD/build OUT=$PWD/out -j2 all
#
# Real dependencies: the database depends on the sweep input and knit-meso; each case result
# on its case file, the database and knit-macro; each figure on the results it draws; the
# report on everything. A second run does nothing; -j2 runs independent cases side by side.
#
# DB_SOURCE = auto | sweep | synth. auto uses `knit-meso sweep $(SWEEP_INPUT)` when knit-meso has
# the sweep subcommand and the input exists, and otherwise the SYNTHETIC stand-in
# `knit-meso synth` (the report says which one was used, from $(OUT)/database.source). A
# SWEEP_INPUT given on the command line or in the environment must exist (session 45: a
# misspelt one fell back on the stand-in); the default one may be missing.
# Outputs: $(OUT)/database.h5, $(OUT)/cases/NAME.json (the case with the database path set),
# $(OUT)/results/NAME/ (knit-macro's output directory), $(OUT)/results/NAME.status (exit code
# and wall time), $(OUT)/logs/, $(OUT)/figures/*.png, $(OUT)/report.md.

ROOT ?= $(abspath $(dir $(lastword $(MAKEFILE_LIST)))/..)
BUILD ?= $(ROOT)/build
OUT ?= $(ROOT)/out
PY ?= /usr/bin/python3
MESO := $(BUILD)/bin/knit-meso
MACRO := $(BUILD)/bin/knit-macro
SWEEP_INPUT ?= $(ROOT)/cases/sweep/default.json
SWEEP_THREADS ?= 2
DB_SOURCE ?= auto
# Sensitivity of the observables to the unit-cell parameters (issue #12; CSV columns parameter,
# value, observable, result: scripts/figures/sensitivity.py). Drawn and reported when it exists.
SENSITIVITY ?= $(ROOT)/cases/calibration/sensitivity.csv
comma := ,
CASEDIR := $(ROOT)/cases/paper
FIGPY := $(ROOT)/scripts/figures
DB := $(OUT)/database.h5
RES := $(OUT)/results
FIG := $(OUT)/figures
LOGS := $(OUT)/logs

export MPLBACKEND := Agg

# A subcommand exists when `knit-meso --help` lists it.
MESO_SUBCOMMANDS := $(shell "$(MESO)" --help 2>/dev/null | sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p')
# A SWEEP_INPUT given (command line or environment) that does not exist is a mistake, not a
# reason to fall back on the synthetic stand-in (session 45's red team: a misspelt input gave
# `database: synth` with exit 0, and replaced an earlier sweep's database).
# (Not for clean, nor for DB_SOURCE=synth, which read no sweep input; the review of session 45.)
ifneq ($(filter command line environment,$(origin SWEEP_INPUT)),)
ifeq ($(filter clean,$(MAKECMDGOALS))$(filter synth,$(DB_SOURCE)),)
ifneq ($(words $(SWEEP_INPUT)),1)
$(error SWEEP_INPUT="$(SWEEP_INPUT)" holds a space, which make cannot carry in a path: give a path without spaces)
endif
ifeq ($(wildcard $(SWEEP_INPUT)),)
$(error SWEEP_INPUT=$(SWEEP_INPUT) does not exist (relative paths are taken from $(CURDIR)): give an existing sweep input, or leave SWEEP_INPUT out for cases/sweep/default.json)
endif
endif
endif
HAVE_SWEEP := $(if $(and $(filter sweep,$(MESO_SUBCOMMANDS)),$(wildcard $(SWEEP_INPUT))),yes)
HAVE_CELL := $(if $(filter cell,$(MESO_SUBCOMMANDS)),yes)
ifeq ($(DB_SOURCE),auto)
  DB_MODE := $(if $(HAVE_SWEEP),sweep,synth)
else
  DB_MODE := $(DB_SOURCE)
endif
DB_INPUTS := $(if $(filter sweep,$(DB_MODE)),$(SWEEP_INPUT))

CASES := $(sort $(basename $(notdir $(wildcard $(CASEDIR)/*.json))))
STATUS := $(CASES:%=$(RES)/%.status)
st = $(addprefix $(RES)/,$(addsuffix .status,$(1)))

# An OUT other than the checkout's out/ is written only if it is new, empty or an earlier run's
# output (the marker .knitscale-output, as scripts/run.sh; docs/reproduction.md): the targets
# below write figures/, results/, logs/ ... into it, so another directory's files are not ours
# to replace. Checked when the makefile is read, for every goal but clean (which has its own).
# An OUT make cannot carry as one word (a space: `clean` removed a user's directory and the
# caller's out/..., session 36) is refused for every goal, clean included (scripts/run.sh also
# refuses $ ; # : , ~ and quotes, which make expands or parses before this is read).
ifneq ($(words $(OUT)),1)
$(error OUT="$(OUT)" holds a space (or is empty): make cannot carry it as one path; give a path of letters, digits and / . _ - + @)
endif
ifneq ($(filter-out clean,$(or $(MAKECMDGOALS),all)),)
OUT_STATE := $(shell d='$(OUT)'; p=$$(dirname "$$(realpath -m "$$d")"); in=; \
  while [ "$$p" != / ]; do [ -f "$$p/.knitscale-output" ] \
    && grep -q -E '^(for|file): ' "$$p/.knitscale-output" && in=$$p && break; \
    p=$$(dirname "$$p"); done; \
  if [ -n "$$in" ]; then echo inside; \
  elif [ -e "$$d" ] && [ ! -d "$$d" ]; then echo notdir; \
  elif [ "$$d" != '$(ROOT)/out' ] && [ -d "$$d" ] && [ -n "$$(ls -A "$$d")" ] \
       && [ ! -f "$$d/.knitscale-output" ]; then echo foreign; \
  elif [ -f "$$d/.knitscale-output" ] \
       && ! head -n 1 "$$d/.knitscale-output" | grep -q "reproduction pipeline"; then \
    echo other; \
  else mkdir -p "$$d" && { [ -f "$$d/.knitscale-output" ] || echo "knitscale output: the \
reproduction pipeline (scripts/pipeline.mk)" > "$$d/.knitscale-output"; } && echo ours; fi)
# Inside a run's output (its marker has a "for:" or "file:" line; the review of session 46:
# figures/, logs/ and report.md went into a design's output, whose next design was refused).
ifeq ($(OUT_STATE),inside)
$(error OUT=$(OUT) lies inside the output of a knitscale run (an enclosing directory's .knitscale-output says so): the pipeline would change that run's files; give a path outside it)
endif
ifeq ($(OUT_STATE),notdir)
$(error OUT=$(OUT) exists and is not a directory)
endif
ifeq ($(OUT_STATE),foreign)
$(error OUT=$(OUT) is a non-empty directory that is not a knitscale output (no .knitscale-output file): its files are not ours to replace; give a new or empty directory)
endif
ifeq ($(OUT_STATE),other)
$(error OUT=$(OUT) is the output of another knitscale program (its .knitscale-output names it), not of the pipeline: its files are not ours to replace; give another directory)
endif
ifneq ($(OUT_STATE),ours)
$(error OUT=$(OUT): cannot create the directory or its .knitscale-output marker)
endif
endif

.PHONY: all database cases figures report clean meso
.DELETE_ON_ERROR:

all: report
database: $(DB)
# The resolved case files are named here so that make does not treat them as intermediate
# (deleted after the run, remade by the next one).
RESOLVED := $(CASES:%=$(OUT)/cases/%.json)
cases: $(RESOLVED) $(STATUS)

$(MESO) $(MACRO):
	@echo "pipeline: $@ is missing: build first (scripts/build.sh $(BUILD))"; exit 1

# ---- material database ------------------------------------------------------------------------
# database.source holds the mode; it is rewritten only when the mode changes, so switching from
# the stand-in to the sweep rebuilds the database (and everything after it).
# With the inputs' contents (sha256 of the sweep input and of the cell file it names, by
# scripts/figures/input_digest.py): a sweep input edited, or replaced by an older file, or a
# changed cell file rebuilds the database (session 45's red team: make compared time stamps
# only, and a database of the former input stayed).
$(OUT)/database.source: FORCE
	@mkdir -p $(OUT)
	@src="$(DB_MODE) $(abspath $(DB_INPUTS))$(if $(DB_INPUTS), $$($(PY) $(FIGPY)/input_digest.py $(DB_INPUTS) || echo unreadable))"; \
	echo "$$src" | cmp -s - $@ || echo "$$src" > $@

$(DB): $(OUT)/database.source $(MESO) $(DB_INPUTS)
	@mkdir -p $(LOGS)
	@echo "database: $(DB_MODE) -> $@"
	@start=$$(date +%s.%N); \
	if [ "$(DB_MODE)" = sweep ]; then \
	  "$(MESO)" sweep "$(SWEEP_INPUT)" --output $@ --threads $(SWEEP_THREADS) --force --plain > $(LOGS)/database.log 2>&1; \
	else \
	  "$(MESO)" synth --out $@ > $(LOGS)/database.log 2>&1; \
	fi || { echo "database: failed, see $(LOGS)/database.log"; tail -5 $(LOGS)/database.log; exit 1; }; \
	end=$$(date +%s.%N); \
	echo "{\"mode\": \"$(DB_MODE)\", \"seconds\": $$(awk "BEGIN{printf \"%.3f\", $$end - $$start}")}" > $(OUT)/database.time

# ---- cases ------------------------------------------------------------------------------------
$(OUT)/cases/%.json: $(CASEDIR)/%.json $(FIGPY)/resolve_case.py
	@mkdir -p $(OUT)/cases
	@$(PY) $(FIGPY)/resolve_case.py $< $(DB) $@

# knit-macro exits 1 when a load step fails (the converged steps are kept): the pipeline goes on
# and the report shows the failure; the status file records the exit code and the wall time.
# A case whose status says it completed but whose results are gone is run again (FORCE through
# the second expansion; session 36's red team: results/NAME removed, the rerun re-made nothing
# and the report kept its PASS verdicts on data that no longer existed).
# $(call run_case,RESULTS,LOG,LABEL,JSON): the recipe of a case run: knit-macro run $< into
# RESULTS/$*, its output in LOG, the status file $@ (JSON: members before the exit code).
# $(call wrote_json,DIR): `, "wrote": true` when DIR's output marker (.knitscale-output, written
# by knit-macro with every output it writes) is not older than the recipe's start $$s0, else
# false: whether this run wrote its output (session 45's review: knit-macro exits with 1 and
# writes nothing when no load step converges, and the earlier run's output was taken as this
# one's). scripts/figures/results.py, strain_box.current_results and the report read it.
wrote_json = , \"wrote\": $$(if [ -f $(1)/.knitscale-output ] && [ $$(stat -c %Y $(1)/.knitscale-output) -ge $$s0 ]; then echo true; else echo false; fi)
define run_case
@mkdir -p $(1) $(LOGS)
@echo "$(3): $*"
@s0=$$(date +%s); start=$$(date +%s.%N); rc=0; \
"$(MACRO)" run $< --output $(1)/$* > $(2) 2>&1 || rc=$$?; \
end=$$(date +%s.%N); \
echo "{\"case\": \"$*\", $(4)\"exit_code\": $$rc, \"seconds\": $$(awk "BEGIN{printf \"%.3f\", $$end - $$start}")$(call wrote_json,$(1)/$*)}" > $@; \
if [ $$rc -ne 0 ]; then echo "$(3): $* exited with $$rc (see $(2))"; fi
endef
# The prerequisite that forces a rerun when RESULTS/$*.status says the run completed but its
# load_strain.csv is gone (second expansion).
case_gone = $$(if $$(shell grep -qsE '"exit_code". 0[,}]' $(1)/$$*.status && \
    [ ! -f $(1)/$$*/load_strain.csv ] && echo gone),FORCE)
.SECONDEXPANSION:
$(RES)/%.status: $(OUT)/cases/%.json $(DB) $(MACRO) $(call case_gone,$(RES))
	$(call run_case,$(RES),$(LOGS)/$*.log,case,)

# ---- the paper's law beside the energy law (fig07e; issue 11 item 4, session 43) ---------------
# The uniform cases of Sect. 3.1.2 run again with "law": "paper" (the eq. 17 surfaces of the same
# database) into results_paper_law/; drawn beside the default law's runs, not judged by the report.
LAWCMP := s312_uniform_45_course s312_uniform_45_wale s312_uniform_65_course s312_uniform_65_wale
RES_PAPER := $(OUT)/results_paper_law
LAWCMP_STATUS := $(LAWCMP:%=$(RES_PAPER)/%.status)
.SECONDARY: $(LAWCMP:%=$(OUT)/cases_paper_law/%.json)
$(OUT)/cases_paper_law/%.json: $(CASEDIR)/%.json $(FIGPY)/resolve_case.py
	@mkdir -p $(OUT)/cases_paper_law
	@$(PY) $(FIGPY)/resolve_case.py $< $(DB) $@ paper
$(RES_PAPER)/%.status: $(OUT)/cases_paper_law/%.json $(DB) $(MACRO) $(call case_gone,$(RES_PAPER))
	$(call run_case,$(RES_PAPER),$(LOGS)/paper_law_$*.log,case (paper's law),\"law\": \"paper\"$(comma) )

# ---- unit cells (Fig. 5) ----------------------------------------------------------------------
# The sweep's own cell parameters (scripts/figures/sweep_cell.py; session 45's red team: Fig. 5
# drew the default cell beside a database swept with another yarn diameter). Remade with
# database.source, which follows the input's and its cell file's contents.
$(OUT)/cells/params.json: $(OUT)/database.source $(FIGPY)/sweep_cell.py
	@mkdir -p $(OUT)/cells
	@$(PY) $(FIGPY)/sweep_cell.py "$(DB_INPUTS)" $@
$(OUT)/cells/%/cell.json: $(MESO) $(OUT)/cells/params.json
	@mkdir -p $(OUT)/cells $(LOGS)
	@"$(MESO)" cell --loop-length $* --config $(OUT)/cells/params.json --out $(OUT)/cells/$* > $(LOGS)/cell_$*.log 2>&1

# ---- figures ----------------------------------------------------------------------------------
FIGURES :=
# $(call draw,COMMAND,OUT.png): a figure script that fails does not stop the pipeline: the
# error goes to logs/figures/NAME.log and the PNG says the figure is missing; the placeholder is
# dated 1970 so that the next run tries the figure again.
draw = mkdir -p $(FIG) $(LOGS)/figures; $(1) > $(LOGS)/figures/$(notdir $(basename $(2))).log 2>&1 || { \
  echo "figure: $(notdir $(2)) failed, see $(LOGS)/figures/$(notdir $(basename $(2))).log"; \
  $(PY) $(FIGPY)/plots.py --results $(RES) placeholder --title "$(notdir $(2))" --message "the figure script failed (logs/figures)" --out $(2) \
  && touch -d @0 $(2); }

# The figures of knit-macro's results (plots.py deformed / fields / load) are drawn in two
# batches, one Python process each (scripts/figures/batch.py: the imports of matplotlib and
# numpy cost more than most figures; docs/build.md): PLOT_A (the deformed shapes) and PLOT_B
# (fields and load curves) side by side with -j2. A batch is redrawn as a whole when one of its
# inputs changes; a failed figure becomes a placeholder as above.
PLOT_A_FIGS :=
PLOT_A_DEPS :=
PLOT_A_JOBS :=
PLOT_B_FIGS :=
PLOT_B_DEPS :=
PLOT_B_JOBS :=
PLOTJOB = '$(FIG)/$(1).png $(FIGPY)/plots.py --results $(RES) $(2)'

define deformed # name, case, field, step-strain (or "last"), title[, cases sharing the colour scale]
FIGURES += $(FIG)/$(1).png
PLOT_A_FIGS += $(FIG)/$(1).png
PLOT_A_DEPS += $(call st,$(2) $(6))
PLOT_A_JOBS += $(call PLOTJOB,$(1),deformed --case $(2) --field $(3) --at $(4) $(if $(6),--share-limits $(6)) --title "$(5)")
endef

define fields # name, case, title[, sub-command: fields (default) or geometry]
FIGURES += $(FIG)/$(1).png
PLOT_B_FIGS += $(FIG)/$(1).png
PLOT_B_DEPS += $(call st,$(2))
PLOT_B_JOBS += $(call PLOTJOB,$(1),$(or $(4),fields) --case $(2) --title "$(3)")
endef

define load # name, title, cases...
FIGURES += $(FIG)/$(1).png
PLOT_B_FIGS += $(FIG)/$(1).png
PLOT_B_DEPS += $(call st,$(3))
PLOT_B_JOBS += $(call PLOTJOB,$(1),load --title "$(2)" $(3))
endef

# Fig. 5: unit cells (needs `knit-meso cell`).
ifeq ($(HAVE_CELL),yes)
FIGURES += $(FIG)/fig05_cells.png
$(FIG)/fig05_cells.png: $(OUT)/cells/4.5/cell.json $(OUT)/cells/6.5/cell.json $(FIGPY)/cells.py
	@$(call draw,$(PY) $(FIGPY)/cells.py --out $@ $(OUT)/cells/4.5 $(OUT)/cells/6.5,$@)
endif

# Fig. 6: response surfaces at 6.5 mm with the data points, and beside it the energy-based law
# (W, S11, S22 at 6.5 mm with the data; issue 11): one batch (scripts/figures/batch.py).
DB_FIGS := $(FIG)/fig06_response_surfaces.png $(FIG)/fig06e_energy_law.png
FIGURES += $(DB_FIGS)
$(DB_FIGS) &: $(DB) $(FIGPY)/surfaces.py $(FIGPY)/energy_law.py $(FIGPY)/batch.py
	@mkdir -p $(FIG) $(LOGS)/figures
	@$(PY) $(FIGPY)/batch.py --logs $(LOGS)/figures \
	  '$(FIG)/fig06_response_surfaces.png $(FIGPY)/surfaces.py --database $(DB) --loop-length 6.5' \
	  '$(FIG)/fig06e_energy_law.png $(FIGPY)/energy_law.py --database $(DB) --loop-length 6.5 --absent-placeholder'

# Sect. 3.1.2 (Fig. 7): 7a and 7b share their colour scale (the paper compares their uniformity).
$(eval $(call deformed,fig07a_uniform45_wale_E22,s312_uniform_45_wale,E22,0.3,Fig. 7a: l = 4.5 mm wale-wise at 30 % (E22),s312_uniform_65_wale))
$(eval $(call deformed,fig07b_uniform65_wale_E22,s312_uniform_65_wale,E22,0.3,Fig. 7b: l = 6.5 mm wale-wise at 30 % (E22),s312_uniform_45_wale))
$(eval $(call load,fig07c_convergence,Fig. 7c: convergence wale-wise l = 4.5 mm,conv7c_p3h1 conv7c_p5h1 conv7c_p7h1 conv7c_p3h4 conv7c_p5h4 conv7c_p7h4))
$(eval $(call load,fig07d_load_strain,Fig. 7d: uniform stitch values,s312_uniform_45_course s312_uniform_45_wale s312_uniform_65_course s312_uniform_65_wale))
FIGURES += $(FIG)/fig07e_laws_load_strain.png
PLOT_B_FIGS += $(FIG)/fig07e_laws_load_strain.png
PLOT_B_DEPS += $(call st,$(LAWCMP)) $(LAWCMP_STATUS)
PLOT_B_JOBS += $(call PLOTJOB,fig07e_laws_load_strain,laws --paper-results $(RES_PAPER) --title "Fig. 7d with both laws: energy (default, solid) and eq. 17 (dashed)" $(LAWCMP))
# Sect. 3.1.3 (Figs. 8-9)
$(eval $(call fields,fig08a_discontinuous_field,s313_discontinuous_course,Fig. 8a: stitch value 4.5 | 6.5 mm))
$(eval $(call deformed,fig09b_discontinuous_course_E11,s313_discontinuous_course,E11,0.3,Fig. 9b: course-wise at 30 % (E11)))
$(eval $(call deformed,fig09d_discontinuous_wale_E22,s313_discontinuous_wale,E22,0.3,Fig. 9d: wale-wise at 30 % (E22)))
$(eval $(call load,fig09e_convergence,Fig. 9e: convergence wale-wise 4.5 | 6.5 mm,conv9e_p3h1 conv9e_p5h1 conv9e_p7h1))
$(eval $(call load,fig09f_load_strain,Fig. 9f: discontinuous grading,s313_discontinuous_course s313_discontinuous_wale))
# Sect. 3.1.4 (Figs. 10-11)
$(eval $(call fields,fig10a_linear_field,s314_linear_course,Fig. 10a: stitch value 4.5 -> 6.5 mm along the wale))
$(eval $(call deformed,fig11b_linear_course_E11,s314_linear_course,E11,0.3,Fig. 11b: course-wise at 30 % (E11)))
$(eval $(call deformed,fig11d_linear_wale_E22,s314_linear_wale,E22,0.3,Fig. 11d: wale-wise at 30 % (E22)))
$(eval $(call load,fig11e_load_strain,Fig. 11e: linear grading,s314_linear_course s314_linear_wale))
# Sect. 3.1.5 (Fig. 12)
$(eval $(call fields,fig12a_diagonal_field,s315_diagonal_45deg_vertical,Fig. 12a: stitch value and knitting direction (alpha = pi/4)))
$(eval $(call deformed,fig12c_diagonal_E11,s315_diagonal_45deg_vertical,E11,0.3,Fig. 12c: vertical test at 30 % (E11)))
$(eval $(call deformed,fig12d_diagonal_E22,s315_diagonal_45deg_vertical,E22,0.3,Fig. 12d: vertical test at 30 % (E22)))
$(eval $(call load,fig12f_load_strain,Fig. 12f: 45 deg knitting direction,s315_diagonal_45deg_vertical))
# Sect. 3.2.1 (Figs. 13-14)
$(eval $(call fields,fig13_bilinear_fields,s321_bilinear_diagonal,Fig. 13: bilinear stitch value and knitting direction))
$(eval $(call deformed,fig14a_bilinear_E11,s321_bilinear_diagonal,E11,last,Fig. 14a: diagonal test u1 = u2 = 10 mm (E11)))
$(eval $(call deformed,fig14b_bilinear_E22,s321_bilinear_diagonal,E22,last,Fig. 14b: diagonal test u1 = u2 = 10 mm (E22)))
$(eval $(call deformed,fig14c_bilinear_E12,s321_bilinear_diagonal,E12,last,Fig. 14c: diagonal test u1 = u2 = 10 mm (E12)))
$(eval $(call load,fig14d_load_strain,Fig. 14d: diagonal tensile test,s321_bilinear_diagonal))
$(eval $(call load,fig14e_mesh_study,Sect. 3.2.1 mesh study (p = 5; h = 1 2 4),s321_bilinear_diagonal mesh321_p5h2 mesh321_p5h4))
# Sect. 3.2.2 (Fig. 15)
$(eval $(call fields,fig15ab_curved_fields,s322_curved_horizontal,Fig. 15a/b: stitch value and knitting direction))
$(eval $(call deformed,fig15c_curved_E11,s322_curved_horizontal,E11,0.3,Fig. 15c: horizontal test at 30 % (E11)))
$(eval $(call deformed,fig15d_curved_E22,s322_curved_horizontal,E22,0.3,Fig. 15d: horizontal test at 30 % (E22)))
$(eval $(call deformed,fig15e_curved_E12,s322_curved_horizontal,E12,0.3,Fig. 15e: horizontal test at 30 % (E12)))
$(eval $(call load,fig15f_load_strain,Fig. 15f: curved patch horizontal test,s322_curved_horizontal))
# Sect. 3.2.3 (Fig. 16)
$(eval $(call fields,fig16a_hypar_geometry,s323_hypar_tension,Fig. 16a: geometry of the hyperbolic paraboloid,geometry))
$(eval $(call fields,fig16b_hypar_fields,s323_hypar_tension,Fig. 16b: stitch value and knitting direction))
$(eval $(call deformed,fig16c_hypar_tension_E12,s323_hypar_tension,E12,last,Fig. 16c: diagonal tension ~21 % (E12)))
$(eval $(call deformed,fig16d_hypar_compression_E12,s323_hypar_compression,E12,last,Fig. 16d: diagonal compression ~14 % (E12)))

# The two batches of plots.py figures (grouped targets: one recipe draws all of a batch).
PLOT_SCRIPTS := $(FIGPY)/plots.py $(FIGPY)/results.py $(FIGPY)/batch.py
$(PLOT_A_FIGS) &: $(sort $(PLOT_A_DEPS)) $(PLOT_SCRIPTS)
	@mkdir -p $(FIG) $(LOGS)/figures
	@$(PY) $(FIGPY)/batch.py --logs $(LOGS)/figures $(PLOT_A_JOBS)
$(PLOT_B_FIGS) &: $(sort $(PLOT_B_DEPS)) $(PLOT_SCRIPTS)
	@mkdir -p $(FIG) $(LOGS)/figures
	@$(PY) $(FIGPY)/batch.py --logs $(LOGS)/figures $(PLOT_B_JOBS)

# Sensitivity (issue #12): only when the calibration study has written its table.
ifneq ($(wildcard $(SENSITIVITY)),)
FIGURES += $(FIG)/sensitivity.png
$(FIG)/sensitivity.png: $(SENSITIVITY) $(FIGPY)/sensitivity.py
	@$(call draw,$(PY) $(FIGPY)/sensitivity.py $(SENSITIVITY) --out $@,$@)
endif


# ---- knitting maps (issue 13, docs/design.md) ----------------------------------------------------
# `knit-macro knitmap` on the planar paper cases, then the PNG by scripts/figures/knitmap.py.
KNITMAPS := s312_uniform_45_course s313_discontinuous_course s314_linear_course \
  s315_diagonal_45deg_vertical s322_curved_horizontal
KNITMAP_FIGURES := $(KNITMAPS:%=$(FIG)/knitmap_%.png)
# As a case's or a design's: a knitting map that fails (e.g. a database whose loop lengths do not
# cover the case's: exit 2) does not stop the pipeline; its status file records the exit code,
# the report and the figure say so (session 45: a database of one loop length stopped the main
# job at the first knitting map, after every case had run, and left no report). A status that
# says it completed while summary.txt is gone is run again (the cases' FORCE rule, above).
KNITMAP_STATUS := $(KNITMAPS:%=$(OUT)/knitmap/%.status)
knitmap_gone = $$(if $$(shell grep -qsE '"exit_code". 0[,}]' $(OUT)/knitmap/$$*.status && \
    [ ! -f $(OUT)/knitmap/$$*/summary.txt ] && echo gone),FORCE)
$(OUT)/knitmap/%.status: $(OUT)/cases/%.json $(DB) $(MACRO) $(knitmap_gone)
	@mkdir -p $(OUT)/knitmap $(LOGS)
	@s0=$$(date +%s); rc=0; "$(MACRO)" knitmap $< --output $(OUT)/knitmap/$* > $(LOGS)/knitmap_$*.log 2>&1 || rc=$$?; \
	echo "{\"knitmap\": \"$*\", \"exit_code\": $$rc$(call wrote_json,$(OUT)/knitmap/$*)}" > $@; \
	if [ $$rc -ne 0 ]; then echo "knitmap: $* exited with $$rc (see $(LOGS)/knitmap_$*.log)"; fi
.PHONY: knitmaps
knitmaps: $(KNITMAP_STATUS) $(KNITMAP_FIGURES)

# ---- inverse design (issue 13, docs/design.md) -------------------------------------------------
# `knit-macro design` on the examples of cases/design (their case files resolved to the
# pipeline's database), then the objective history and designed fields by
# scripts/figures/design.py. Outputs: $(OUT)/design/NAME/ (history.csv, summary.txt, case.json,
# run/), $(OUT)/design/NAME.status (exit code and wall time), figures/design_NAME.png.
DESIGNS := uniform_load graded_wale diagonal_linear
DESIGN_CASES := uniform_wale graded_wale_case diagonal_case
DESIGN_INPUTS := $(addprefix $(OUT)/design/inputs/,$(addsuffix .json,$(DESIGNS) $(DESIGN_CASES)))
DESIGN_STATUS := $(DESIGNS:%=$(OUT)/design/%.status)
DESIGN_FIGURES := $(DESIGNS:%=$(FIG)/design_%.png)
$(OUT)/design/inputs/%.json: $(ROOT)/cases/design/%.json $(FIGPY)/resolve_case.py
	@mkdir -p $(OUT)/design/inputs
	@$(PY) $(FIGPY)/resolve_case.py $< $(DB) $@
# Exit 1 (iteration limit, failed solve) does not stop the pipeline: the report shows it.
$(OUT)/design/%.status: $(DESIGN_INPUTS) $(DB) $(MACRO)
	@mkdir -p $(LOGS)
	@echo "design: $*"
	@s0=$$(date +%s); start=$$(date +%s.%N); rc=0; \
	"$(MACRO)" design $(OUT)/design/inputs/$*.json --output $(OUT)/design/$* > $(LOGS)/design_$*.log 2>&1 || rc=$$?; \
	end=$$(date +%s.%N); \
	echo "{\"design\": \"$*\", \"exit_code\": $$rc, \"seconds\": $$(awk "BEGIN{printf \"%.3f\", $$end - $$start}")$(call wrote_json,$(OUT)/design/$*)}" > $@; \
	if [ $$rc -ne 0 ]; then echo "design: $* exited with $$rc (see $(LOGS)/design_$*.log)"; fi
DESIGN_FIG_ARGS_graded_wale := --section E22
# The design figures, and the knitting-map figures (`knitmaps`; part of `all` since session 39,
# when the main job drew no knitting map although the docs promised them): one batch
# each (scripts/figures/batch.py, as the plots above).
DESIGN_JOB = '$(FIG)/design_$(1).png $(FIGPY)/design.py $(OUT)/design/$(1) --design $(OUT)/design/inputs/$(1).json --status $(OUT)/design/$(1).status $(DESIGN_FIG_ARGS_$(1)) --title "design: $(1)"'
KNITMAP_JOB = '$(FIG)/knitmap_$(1).png $(FIGPY)/knitmap.py $(OUT)/knitmap/$(1) --status $(OUT)/knitmap/$(1).status --title "knitting map: $(1)"'
$(DESIGN_FIGURES) &: $(DESIGN_STATUS) $(FIGPY)/design.py $(FIGPY)/batch.py
	@mkdir -p $(FIG) $(LOGS)/figures
	@$(PY) $(FIGPY)/batch.py --logs $(LOGS)/figures $(foreach d,$(DESIGNS),$(call DESIGN_JOB,$(d)))
$(KNITMAP_FIGURES) &: $(KNITMAP_STATUS) $(FIGPY)/knitmap.py $(FIGPY)/batch.py
	@mkdir -p $(FIG) $(LOGS)/figures
	@$(PY) $(FIGPY)/batch.py --logs $(LOGS)/figures $(foreach k,$(KNITMAPS),$(call KNITMAP_JOB,$(k)))
.PHONY: designs
designs: $(DESIGN_STATUS) $(DESIGN_FIGURES)
# The resolved inputs are kept (not intermediates): a second run does nothing.
.SECONDARY: $(DESIGN_INPUTS)
$(OUT)/report.md: $(DESIGN_STATUS) $(DESIGN_FIGURES) $(KNITMAP_STATUS) $(KNITMAP_FIGURES)

figures: $(FIGURES) knitmaps designs

# What needs knit-meso only: the database and the figures drawn from it, from the unit cells
# (Fig. 5) or from the calibration table. scripts/run.sh makes these while knit-macro is still
# being compiled (the last compiles and links leave a core idle), so that `all` then only runs
# the cases, designs, their figures and the report.
MESO_ONLY := $(DB) $(DB_FIGS) $(filter $(FIG)/fig05_cells.png $(FIG)/sensitivity.png,$(FIGURES))
meso: $(MESO_ONLY)

# ---- report -----------------------------------------------------------------------------------
$(OUT)/report.md: $(STATUS) $(FIGURES) $(DB) $(OUT)/database.source $(ROOT)/scripts/report.py \
  $(ROOT)/scripts/report_checks.py $(ROOT)/scripts/law_near_visited.py \
  $(ROOT)/scripts/cell_paths.py $(ROOT)/scripts/strain_box.py $(ROOT)/scripts/law_small_strain.py \
  $(ROOT)/scripts/law_uniaxial.py $(ROOT)/scripts/law_shear.py \
  $(ROOT)/scripts/law_held_out.py \
  $(FIGPY)/energy_law.py \
  $(FIGPY)/results.py $(FIGPY)/sensitivity.py $(wildcard $(SENSITIVITY))
	@$(PY) $(ROOT)/scripts/report.py --out-dir $(OUT) --database $(DB) --cells "$(HAVE_CELL)" \
	  --sensitivity "$(SENSITIVITY)" --cases-dir $(CASEDIR) \
	  --expect-designs "$(DESIGNS)" --designs-dir $(ROOT)/cases/design \
	  --expect-figures "$(notdir $(FIGURES) $(DESIGN_FIGURES) $(KNITMAP_FIGURES))" > $(LOGS)/report.log 2>&1 \
	  || { cat $(LOGS)/report.log; exit 1; }
	@echo "report: $@"

report: $(OUT)/report.md

# Only an output directory of the pipeline's: the checkout's out/, or one holding the marker
# that scripts/run.sh writes (another directory's figures/ or logs/ are not ours to delete).
clean:
	@if [ "$(OUT)" != "$(ROOT)/out" ] && [ ! -f "$(OUT)/.knitscale-output" ]; then \
	  echo "clean: $(OUT) holds no .knitscale-output file: not a pipeline output, nothing removed" >&2; \
	  exit 2; fi
	@if [ -f "$(OUT)/.knitscale-output" ] \
	  && ! head -n 1 "$(OUT)/.knitscale-output" | grep -q "reproduction pipeline"; then \
	  echo "clean: $(OUT) is another program's output, not the pipeline's: nothing removed" >&2; \
	  exit 2; fi
	rm -rf "$(OUT)/database.h5" "$(OUT)/database.source" "$(OUT)/database.time" "$(OUT)/cases" \
	  "$(OUT)/database.h5.parts" \
	  "$(OUT)/logs" "$(OUT)/cells" "$(OUT)/knitmap" "$(OUT)/design" "$(OUT)/report.md" \
  "$(OUT)/cases_paper_law"
# figures/ and results/ file by file: what the pipeline writes there (its figures and their
# temporaries; each case's status, output directory, partial directories, lock and the completed
# output a stopped rerun kept beside it, NAME.last-completed[-PID], session 46), then the
# directory if that emptied it (session 36's red team: a user's figures/my_plot.png and
# results/my_analysis/ went with the whole directories).
	@for f in $(FIGURES) $(KNITMAP_FIGURES) $(DESIGN_FIGURES); do \
	  rm -f "$$f" "$$f.tmp.png"; done
	@for c in $(CASES); do \
	  rm -rf "$(RES)/$$c" "$(RES)/$$c.status" "$(RES)/$$c.lock" "$(RES)/$$c".partial-* \
	    "$(RES)/$$c.last-completed" "$(RES)/$$c".last-completed-*; done
	@for c in $(LAWCMP); do \
	  rm -rf "$(RES_PAPER)/$$c" "$(RES_PAPER)/$$c.status" "$(RES_PAPER)/$$c.lock" \
	    "$(RES_PAPER)/$$c".partial-* "$(RES_PAPER)/$$c.last-completed" \
	    "$(RES_PAPER)/$$c".last-completed-*; done
	@for d in "$(FIG)" "$(RES)" "$(RES_PAPER)"; do \
	  if [ -d "$$d" ]; then rmdir "$$d" 2>/dev/null \
	    || echo "clean: kept $$d: it holds files the pipeline did not write" >&2; fi; done

FORCE:
