"""Grading: feedback in the notebook, the assignment generator, the sandboxed grader and the handout.

check            ``check(exercise_id, fn)``: a notebook's feedback on an exercise's public cases
judge            one case judged: the student's call, the expected answer, the comparison
assign           ``robocourse assign``: student notebooks (and their data files) from ``solutions/``
data             the data an assignment's notebook works on, one JSON file each
submission       a submitted notebook read as hostile input, or rejected with a flag
protocol         the job directory and the records grader and worker exchange
transport        plain data between grader and worker: bounded, no-follow reads of hostile files
kit              the code the worker runs with: its own modules and the data, no robokit
barrier          the worker's import barrier: check and assignment_data offered, the rest refused
worker           the process that runs a submission's cells and calls its functions
sandbox          the worker's limits, namespaces, uid and root filesystem
syscall_filter   no_new_privs and a seccomp filter: no namespaces, mounts or privilege gain
filesystem_view  the worker's root filesystem as an allowlist (root only)
job_cgroup       a control group that bounds a job's memory, processes and CPU, and ends it (root only)
grader           ``robocourse grade``: cases from the secret seed, expected answers, scores, flags
budget           the grader's reading and judging of one submission, in a child under a memory and time budget
reports          the gradebook, feedback files and Gradescope results
rubrics          the written questions' rubrics and the grading guide for TAs beside the gradebook
safetext         student text escaped for feedback, CSV and Markdown
gradescope       an autograder zip for Gradescope
handout          ``robocourse student-kit``: the zip students get, lessons and blank assignments, no solutions
selfcheck        the course build's step that grades every solution (full marks) and blank (zero)
"""
from robocourse.grading.check import PUBLIC_SEED, check

__all__ = ["check", "PUBLIC_SEED"]
