"""`mpc lsp` in a real editor: Neovim (headless), its built-in LSP client started on
`mpc lsp --stdio` by a Lua config, opens a definition with a wrong link name and writes the
diagnostics it shows to a file.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from tests.lsp.definitions import EXPORT, HEAD

EXAMPLES = Path(__file__).resolve().parents[2] / "specs" / "examples"

CONFIG = """\
local out = os.getenv("MPC_NVIM_OUT")
vim.defer_fn(function() vim.cmd("cquit 2") end, 60000)  -- no diagnostics in a minute: fail
vim.api.nvim_create_autocmd("BufReadPost", {pattern = "*.yml", callback = function(args)
  local client = vim.lsp.start_client({
    name = "mpc",
    cmd = {os.getenv("MPC_PYTHON"), "-m", "mpc.cli.main", "lsp", "--stdio"},
    root_dir = vim.fn.getcwd(),
    handlers = {["textDocument/publishDiagnostics"] = function(err, result, ctx, config)
      vim.lsp.diagnostic.on_publish_diagnostics(err, result, ctx, config)
      local shown = {}
      for _, d in ipairs(vim.diagnostic.get(args.buf)) do
        table.insert(shown, {lnum = d.lnum, col = d.col, end_col = d.end_col, message = d.message,
                             severity = d.severity, source = d.source,
                             code = d.user_data and d.user_data.lsp and d.user_data.lsp.code})
      end
      local f = io.open(out, "w")
      f:write(vim.fn.json_encode(shown))
      f:close()
      vim.cmd("qall!")
    end},
  })
  vim.lsp.buf_attach_client(args.buf, client)
end})
"""

DEFINITION = HEAD + "    remove_beyond: uppr\n" + EXPORT


def test_neovim_shows_the_diagnostics(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "arm.urdf", tmp_path / "arm.urdf")
    shutil.copytree(EXAMPLES / "meshes", tmp_path / "meshes")
    (tmp_path / "arm_model.yml").write_text(DEFINITION, encoding="utf-8")
    (tmp_path / "init.lua").write_text(CONFIG, encoding="utf-8")
    out = tmp_path / "diagnostics.json"
    env = {**os.environ, "MPC_NVIM_OUT": str(out), "MPC_PYTHON": sys.executable,
           "MPC_CACHE_DIR": str(tmp_path / "cache"), "XDG_CONFIG_HOME": str(tmp_path / "config"),
           "XDG_DATA_HOME": str(tmp_path / "data"), "XDG_STATE_HOME": str(tmp_path / "state")}
    run = subprocess.run(["nvim", "--headless", "-n", "-i", "NONE", "-u", "init.lua", "arm_model.yml"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
                         stdin=subprocess.DEVNULL)
    assert run.returncode == 0, run.stderr
    (shown,) = json.loads(out.read_text(encoding="utf-8"))
    assert shown == {"lnum": 8, "col": 19, "end_col": 23, "severity": 1, "source": "mpc", "code": "E0310",
                     "message": "remove_beyond refers to unknown link 'uppr'; did you mean 'upper'?\n"
                                "hint: there are: upper, lower, base"}


ASK = """\
local out = os.getenv("MPC_NVIM_OUT")
vim.defer_fn(function() vim.cmd("cquit 2") end, 60000)  -- no answers in a minute: fail
local asked = false
vim.api.nvim_create_autocmd("BufReadPost", {pattern = "*.yml", callback = function(args)
  local client_id
  client_id = vim.lsp.start_client({
    name = "mpc",
    cmd = {os.getenv("MPC_PYTHON"), "-m", "mpc.cli.main", "lsp", "--stdio"},
    root_dir = vim.fn.getcwd(),
    handlers = {["textDocument/publishDiagnostics"] = function()
      if asked then return end
      asked = true
      vim.schedule(function()
        local client = vim.lsp.get_client_by_id(client_id)
        local answers = {}
        for _, at in ipairs({{14, 18}, {17, 24}, {19, 29}}) do
          local params = {textDocument = {uri = vim.uri_from_bufnr(args.buf)},
                          position = {line = at[1], character = at[2]}}
          local answer = client.request_sync("textDocument/completion", params, 30000, args.buf)
          local labels = {}
          for _, item in ipairs(answer.result.items) do table.insert(labels, item.label) end
          table.insert(answers, labels)
        end
        local f = io.open(out, "w")
        f:write(vim.fn.json_encode(answers))
        f:close()
        vim.cmd("qall!")
      end)
    end},
  })
  vim.lsp.buf_attach_client(args.buf, client_id)
end})
"""


def test_neovim_completes_names_where_they_are(tmp_path: Path) -> None:
    """Completion asked by Neovim's client: a child's joint parent (block and flow style) and
    the joints of a pose written as a flow mapping."""
    from tests.lsp.test_names_in_context import JOINTS, TWO

    for name in ("arm.urdf", "gripper.urdf"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    shutil.copytree(EXAMPLES / "meshes", tmp_path / "meshes")
    (tmp_path / "two.yml").write_text(TWO, encoding="utf-8")
    (tmp_path / "init.lua").write_text(ASK, encoding="utf-8")
    out = tmp_path / "answers.json"
    env = {**os.environ, "MPC_NVIM_OUT": str(out), "MPC_PYTHON": sys.executable,
           "MPC_CACHE_DIR": str(tmp_path / "cache"), "XDG_CONFIG_HOME": str(tmp_path / "config"),
           "XDG_DATA_HOME": str(tmp_path / "data"), "XDG_STATE_HOME": str(tmp_path / "state")}
    run = subprocess.run(["nvim", "--headless", "-n", "-i", "NONE", "-u", "init.lua", "two.yml"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
                         stdin=subprocess.DEVNULL)
    assert run.returncode == 0, run.stderr
    block, flow, pose = json.loads(out.read_text(encoding="utf-8"))
    assert block == ["p_base", "p_upper"]
    assert flow == ["g_finger_left", "g_finger_right", "g_palm", "g_tcp", "p_base", "p_upper"]
    assert pose[:len(JOINTS)] == JOINTS
