/* rtsh — the command table (commands.h): one entry per command; the
 * handlers live in commands.c (help, quit, clear), cmd_scene.c, cmd_step.c
 * and cmd_edit.c, the lookup and argument helpers in commands.c, which read
 * the table the shell is handed (command_table_install, below). */
#include "shell/commands.h"
#include "shell/suggest.h"

#define SUBS_CAMERA "pos|dir|lookat|fov|move|turn"
#define SUBS_LIGHT "pos|move|brightness|color"
#define SUBS_OBJECT "move|rotate|scale|color|set"

const command command_table[] = {
	{"load", NULL, "load FILE", 1, 1, {"@scene"},
	 "replace the scene by a .rt file, a model (.obj .ply .stl) on a framed stage, or a glTF scene (.gltf "
	 ".glb: its cameras, lights and materials); on any error the current scene stays",
	 cmd_load},
	{"save", NULL, "save @images|FILE.ans|FILE.rt", 1, 1, {"@output"}, /* @images: image.c's formats */
	 "write the image (full resolution, rendered first if needed), the picture as ANSI text, or the scene",
	 cmd_save},
	{"render", NULL, "render", 0, 0, {NULL},
	 "render at full resolution now, with progress; Ctrl-C stops it", cmd_render},
	{"set", NULL, "set\nset KEY\nset KEY VALUE", 0, 2, {"@setting", "@value"},
	 "list the settings, or show or change one (help set: each with its values)",
	 cmd_set},
	{"list", "ls", "list [cameras|lights|objects]", 0, 1, {"cameras|lights|objects"},
	 "the cameras, ambient, lights and objects with their numbers and fields", cmd_list},
	{"camera", "cam",
	 "camera\ncamera N\ncamera pos X,Y,Z\ncamera dir X,Y,Z\ncamera lookat X,Y,Z\ncamera fov DEG\n"
	 "camera move DX,DY,DZ\ncamera turn YAW,PITCH",
	 0, 2, {"@camera|" SUBS_CAMERA},
	 "show the active camera, switch to camera N, or edit the active one (move and turn: camera axes)",
	 cmd_camera},
	{"light", NULL,
	 "light\nlight N\nlight N pos X,Y,Z\nlight N move DX,DY,DZ\nlight N brightness B\nlight N color R,G,B",
	 0, 3, {"@light", SUBS_LIGHT}, "list the lights, show light N, or edit it", cmd_light},
	{"object", "obj",
	 "object\nobject N\nobject N move DX,DY,DZ\nobject N rotate RX,RY,RZ\nobject N scale SX,SY,SZ\n"
	 "object N color R,G,B\nobject N set KEY=VALUE",
	 0, 3, {"@object", SUBS_OBJECT, "@key"},
	 "list the objects, show object N, or edit it (move in world axes, rotate in degrees about X, Y, Z)",
	 cmd_object},
	{"ambient", NULL, "ambient\nambient brightness B\nambient color R,G,B", 0, 2, {"brightness|color"},
	 "show or edit the ambient light", cmd_ambient},
	{"add", NULL, "add LINE", 1, CMD_ANY, {"@element"},
	 "add an element written as a .rt line (A and C replace theirs, c adds a camera)", cmd_add},
	{"delete", "del rm", "delete object N\ndelete light N\ndelete camera N", 1, 2,
	 {"object|light|camera", "@ref"}, "remove an object, a light or a camera", cmd_delete},
	{"undo", NULL, "undo [N]", 0, 1, {NULL},
	 "undo the last scene edit, or the last N (a burst of keys in view is one)", cmd_undo},
	{"redo", NULL, "redo [N]", 0, 1, {NULL}, "redo the last undone edit, or the last N", cmd_redo},
	{"generate", "gen", "generate N [SEED]", 1, 2, {NULL},
	 "replace the scene with N random objects; the same seed gives the same scene", cmd_generate},
	{"next", NULL, "next", 0, 0, {NULL},
	 "open the next .rt file of the scene's folder (settings are remembered per scene)", cmd_next},
	{"prev", "previous", "prev", 0, 0, {NULL}, "open the previous .rt file of the scene's folder",
	 cmd_prev},
	{"view", NULL, "view", 0, 0, {NULL},
	 "full-screen key mode: arrow keys move the camera or a selected object on a fast preview; Esc returns",
	 cmd_view},
	{"turntable", NULL, "turntable [SECONDS]", 0, 1, {NULL},
	 "key mode with the camera spinning about the scene's centre, a turn in SECONDS (8); any key stops it",
	 cmd_turntable},
	{"show", NULL, "show [COLUMNS]", 0, 1, {NULL},
	 "print the picture on standard output (half blocks; plain characters without colour)", cmd_show},
	{"source", ".", "source FILE", 1, 1, {"@file"}, "run a command file", cmd_source},
	{"help", "?", "help [COMMAND]", 0, 1, {"@command"}, "the commands, or one command's usage",
	 cmd_help},
	{"clear", NULL, "clear", 0, 0, {NULL}, "clear the command area", cmd_clear},
	{"quit", "exit", "quit\nquit!", 0, 0, {NULL},
	 "leave rtsh (Ctrl-D too); the terminal is restored. With edits not saved as .rt, asks once (quit or\n"
	 "Ctrl-D again leaves); quit! does not ask, nor do -q and command files",
	 cmd_quit},
};
const size_t command_count = sizeof command_table / sizeof command_table[0];

const command *command_find(const char *word, char *msg, size_t size)
{
	return command_lookup(command_table, command_count, word, msg, size);
}

bool suggest_command(const char *word, char *buf, size_t size)
{
	return suggest_command_in(command_table, command_count, word, buf, size);
}

void command_table_install(shell *sh)
{
	sh->commands = command_table;
	sh->ncommands = command_count;
}
